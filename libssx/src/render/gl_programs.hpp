#pragma once
// OpenGL programs for the osmesa engine (a current context is needed to call them).
#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>
#include <GL/glext.h>

namespace ssx::detail {

/// The program of a vertex and a fragment shader (shaders::kVersion, then `definition`, then the
/// source); throws Error with the compiler's message when one does not compile or they do not link.
GLuint link(const char* definition, const char* vertex_source, const char* fragment_source);

}  // namespace ssx::detail
