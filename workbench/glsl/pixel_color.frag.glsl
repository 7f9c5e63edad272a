#version 330
#include "colormap.glsl"
in float light;
in float coord;
#ifdef MISSING
flat in float no_result;
#endif
out vec4 frag_color;

void main() {
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
