#version 330
// element_color path: one colour per element (flat varying), flat lighting as the flat path;
// with MISSING an element without a finite value in the no-result colour
#include "headlight.glsl"
#include "colormap.glsl"
in vec3 eye_position;
flat in float coord;
#ifdef MISSING
flat in float no_result;
#endif
out vec4 frag_color;

void main() {
    float light = headlight(cross(dFdx(eye_position), dFdy(eye_position)), eye_position);
#ifdef MISSING
    if (no_result > 0.5) {
        frag_color = vec4(missing_color * light, 1.0);
        return;
    }
#endif
    vec4 c = colormap_lookup(coord);
#ifdef HIDE
    if (c.a < 0.5) discard;
#endif
    frag_color = vec4(c.rgb * light, 1.0);
}
