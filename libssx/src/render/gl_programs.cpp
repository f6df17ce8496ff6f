// OpenGL programs from the osmesa engine's shader sources (osmesa_shaders.hpp).
#include "render/gl_programs.hpp"
#include "render/osmesa_shaders.hpp"

#include <ssx/error.hpp>

#include <string>

namespace ssx::detail {

namespace {

// a shader from the version line, a definition and the source
GLuint compile(GLenum kind, const char* definition, const char* source) {
  const GLuint shader = glCreateShader(kind);
  const char* parts[] = {shaders::kVersion, definition, source};
  glShaderSource(shader, 3, parts, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[2048] = {};
    glGetShaderInfoLog(shader, sizeof log, nullptr, log);
    throw Error(std::string("osmesa renderer: shader does not compile: ") + log);
  }
  return shader;
}

}  // namespace

GLuint link(const char* definition, const char* vertex_source, const char* fragment_source) {
  const GLuint vs = compile(GL_VERTEX_SHADER, definition, vertex_source),
               fs = compile(GL_FRAGMENT_SHADER, definition, fragment_source);
  const GLuint program = glCreateProgram();
  glAttachShader(program, vs);
  glAttachShader(program, fs);
  glLinkProgram(program);
  GLint ok = 0;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  glDeleteShader(vs);
  glDeleteShader(fs);
  if (!ok) throw Error("osmesa renderer: shaders do not link");
  return program;
}

}  // namespace ssx::detail
