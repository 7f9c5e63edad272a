#version 330
// beams (GL_LINES) and, with POINTS, SPH particles (GL_POINTS) over a mesh path's surface:
// positions relative to the upload origin, a paint per vertex (rgb and how it is used:
// 0 that colour, 1 the colormap at value, 2 the no-result colour) and, for points, the
// radius in model units projected to a point size in pixels
#include "common.vert.glsl"
in vec3 position;
in vec4 paint;
in float value;
flat out vec4 v_paint;
flat out float v_value;
#ifdef POINTS
in float radius;
uniform vec2 viewport;  // (width, height) in pixels
#endif

void main() {
    place(position);
    v_paint = paint;
    v_value = value;
#ifdef POINTS
    // the screen offset of the point one radius away along the eye's up axis
    vec3 up = vec3(view[0][1], view[1][1], view[2][1]);
    vec4 edge = mvp * vec4(position + radius * normalize(up), 1.0);
    vec2 offset = (edge.xy / edge.w - gl_Position.xy / gl_Position.w) * 0.5 * viewport;
    gl_PointSize = max(2.0 * length(offset), 1.0);
#endif
}
