#version 330
// vertex_color path: colormap looked up per vertex, lit colour and transfer alpha interpolated;
// with MISSING the light goes along too and the outputs go to no_result.geom.glsl with the
// vertex's missing flag
#include "common.vert.glsl"
#include "colormap.glsl"
in vec3 position;
in vec3 normal;
in float value;
#ifdef MISSING
in float missing;
out float v_missing;
out float v_light;
#define color v_color
#endif
out vec4 color;

void main() {
    vec3 p = place(position);
    vec4 c = colormap_lookup(colormap_coord(value));
    float l = headlight(mat3(view) * normal, p);
    color = vec4(c.rgb * l, c.a);
#ifdef MISSING
    v_missing = missing;
    v_light = l;
#endif
}
