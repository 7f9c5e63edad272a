#version 330
// element_color path: one colour per element (flat varying), flat lighting as the flat path
#include "headlight.glsl"
#include "colormap.glsl"
in vec3 eye_position;
flat in float coord;
out vec4 frag_color;

void main() {
    float light = headlight(cross(dFdx(eye_position), dFdy(eye_position)), eye_position);
    vec4 c = colormap_color(coord);
#ifdef HIDE
    if (c.a < 0.5) discard;
#endif
    frag_color = vec4(c.rgb * light, 1.0);
}
