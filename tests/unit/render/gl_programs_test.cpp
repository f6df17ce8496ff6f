// The osmesa engine's shader programs (gl_programs.cpp): sources that compile link into a program;
// one that does not compile is an Error with the compiler's message.
#include "render/gl_programs.hpp"

#include <GL/osmesa.h>

#include <ssx/error.hpp>

#include <catch2/catch.hpp>

#include <vector>

using Catch::Contains;

TEST_CASE("gl programs: a program links, a shader that does not compile says why", "[render]") {
  const int attributes[] = {OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 24, OSMESA_PROFILE, OSMESA_CORE_PROFILE,
                            OSMESA_CONTEXT_MAJOR_VERSION, 3, OSMESA_CONTEXT_MINOR_VERSION, 3, 0};
  OSMesaContext context = OSMesaCreateContextAttribs(attributes, nullptr);
  REQUIRE(context != nullptr);
  std::vector<unsigned char> buffer(16 * 16 * 4);
  REQUIRE(OSMesaMakeCurrent(context, buffer.data(), GL_UNSIGNED_BYTE, 16, 16));
  const char* vs = "layout(location = 0) in vec3 p; void main() { gl_Position = vec4(p, 1.0); }\n";
  const char* fs = "out vec4 color; void main() { color = vec4(1.0); }\n";
  const GLuint program = ssx::detail::link("", vs, fs);
  CHECK(program != 0);
  CHECK(glIsProgram(program));
  CHECK_THROWS_WITH(ssx::detail::link("", "void main() { this is not GLSL }\n", fs), Contains("shader does not compile"));
  OSMesaDestroyContext(context);
}
