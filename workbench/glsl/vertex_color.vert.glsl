#version 330
// vertex_color path: colormap looked up per vertex, lit colour and transfer alpha interpolated
#include "common.vert.glsl"
#include "colormap.glsl"
in vec3 position;
in vec3 normal;
in float value;
out vec4 color;

void main() {
    vec3 p = place(position);
    vec4 c = colormap_color(colormap_coord(value));
    color = vec4(c.rgb * headlight(mat3(view) * normal, p), c.a);
}
