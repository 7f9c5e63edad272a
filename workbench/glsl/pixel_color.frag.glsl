#version 330
#include "colormap.glsl"
in float light;
in float coord;
out vec4 frag_color;

void main() {
    vec4 c = colormap_color(coord);
#ifdef HIDE
    if (c.a < 0.5) discard;
#endif
    frag_color = vec4(c.rgb * light, 1.0);
}
