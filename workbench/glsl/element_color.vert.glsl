#version 330
// element_color path: the element's value comes from its provoking (last) vertex, not
// interpolated; with MISSING so does its missing flag (1: the element has no finite value)
#include "common.vert.glsl"
#include "colormap.glsl"
in vec3 position;
in float value;
out vec3 eye_position;
flat out float coord;
#ifdef MISSING
in float missing;
flat out float no_result;
#endif

void main() {
    eye_position = place(position);
    coord = colormap_coord(value);
#ifdef MISSING
    no_result = missing;
#endif
}
