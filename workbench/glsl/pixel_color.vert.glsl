#version 330
// pixel_color path: lighting per vertex, the texture coordinate interpolated for a per-pixel lookup
#include "common.vert.glsl"
#include "colormap.glsl"
in vec3 position;
in vec3 normal;
in float value;
out float light;
out float coord;

void main() {
    vec3 p = place(position);
    light = headlight(mat3(view) * normal, p);
    coord = colormap_coord(value);
}
