#version 330
// element_color path: the element's value comes from its provoking (last) vertex, not interpolated
#include "common.vert.glsl"
#include "colormap.glsl"
in vec3 position;
in float value;
out vec3 eye_position;
flat out float coord;

void main() {
    eye_position = place(position);
    coord = colormap_coord(value);
}
