#version 330
in vec4 color;
#ifdef MISSING
#include "colormap.glsl"
in float light;
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
#ifdef HIDE
    if (color.a < 0.5) discard;
#endif
    frag_color = vec4(color.rgb, 1.0);
}
