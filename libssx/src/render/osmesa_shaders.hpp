#pragma once
// The osmesa render engine's GLSL shaders (render/osmesa_engine.cpp compiles them, prefixed with
// kVersion and a definition of FACE).

namespace ssx::detail::shaders {

// The instanced shaders are compiled twice: for meshes whose faces are flat (box, plane, disc) the
// normal is the same at a face's three corners and is passed flat, not interpolated, as are the
// instance's colour and grid flag. llvmpipe's per-pixel cost grows with what it interpolates: with
// 70 robots, where the ground is most of the picture, a 640 x 480 frame took 6.7-7.0 ms with all
// interpolated and 4.1-4.5 ms with only the world position interpolated (one run each of three).
constexpr const char* kVersion = "#version 330 core\n";
constexpr const char* kSmoothFaces = "#define FACE\n";
constexpr const char* kFlatFaces = "#define FACE flat\n";

constexpr const char* kVertexShader = R"(
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec3 i_position;
layout(location = 3) in vec4 i_rotation;  // quaternion x y z w
layout(location = 4) in vec3 i_scale;
layout(location = 5) in vec4 i_color;
layout(location = 6) in float i_grid;
uniform mat4 u_view_projection;
FACE out vec3 v_normal;
out vec3 v_world;
flat out vec4 v_color;
flat out float v_grid;
vec3 rotate(vec4 q, vec3 v) {
  vec3 t = 2.0 * cross(q.xyz, v);
  return v + q.w * t + cross(q.xyz, t);
}
void main() {
  vec3 world = rotate(i_rotation, a_position * i_scale) + i_position;
  v_world = world;
  v_normal = rotate(i_rotation, a_normal / i_scale);  // inverse transpose of rotation * scale
  v_color = i_color;
  v_grid = i_grid;
  gl_Position = u_view_projection * vec4(world, 1.0);
}
)";

constexpr const char* kFragmentShader = R"(
FACE in vec3 v_normal;
in vec3 v_world;
flat in vec4 v_color;
flat in float v_grid;
uniform vec3 u_sun;  // unit vector towards the sun
uniform vec3 u_eye;
out vec4 o_color;
void main() {
  vec3 n = normalize(v_normal);
  if (!gl_FrontFacing) n = -n;
  vec3 to_eye = normalize(u_eye - v_world);
  float light = 0.3 + 0.45 * max(dot(n, u_sun), 0.0) + 0.3 * max(dot(n, to_eye), 0.0);
  vec3 c = v_color.rgb * min(light, 1.0);
  if (v_grid > 0.5) {
    vec2 w = max(fwidth(v_world.xy), vec2(1e-4));
    vec2 d = abs(fract(v_world.xy + 0.5) - 0.5) / w;
    float line = 1.0 - min(min(d.x, d.y), 1.0);
    float fade = clamp(1.0 - 6.0 * max(w.x, w.y), 0.0, 1.0);  // no moire far away
    c *= 1.0 - 0.35 * line * fade;
  }
  o_color = vec4(c, v_color.a);
}
)";

// what appears small: vertices placed in the world and lit here, drawn as they are
constexpr const char* kBatchVertexShader = R"(
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec4 a_color;
uniform mat4 u_view_projection;
out vec4 v_color;
void main() {
  v_color = a_color;
  gl_Position = u_view_projection * vec4(a_position, 1.0);
}
)";

constexpr const char* kBatchFragmentShader = R"(
in vec4 v_color;
out vec4 o_color;
void main() { o_color = v_color; }
)";

}  // namespace ssx::detail::shaders
