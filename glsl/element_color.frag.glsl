#version 330
// element_color path: one normalised value per triangle (its element's), read by primitive id
#include "headlight.glsl"
#include "colormap.glsl"
uniform sampler2D element_values;
in vec3 eye_position;
out vec4 frag_color;

void main() {
    float light = headlight(cross(dFdx(eye_position), dFdy(eye_position)), eye_position);
    int k = gl_PrimitiveID;
    float t = texelFetch(element_values, ivec2(k % VALUES_WIDTH, k / VALUES_WIDTH), 0).r;
    vec4 c = colormap_lookup(colormap_coord(t));
#ifdef HIDE
    if (c.a < 0.5) discard;
#endif
    frag_color = vec4(c.rgb * light, 1.0);
}
