#version 330
// pixel_color path: lighting per vertex, the texture coordinate interpolated for a per-pixel
// lookup; with MISSING the outputs go to no_result.geom.glsl with the vertex's missing flag
#include "common.vert.glsl"
#include "colormap.glsl"
in vec3 position;
in vec3 normal;
in float value;
#ifdef MISSING
in float missing;
out float v_missing;
#define light v_light
#define coord v_coord
#endif
out float light;
out float coord;

void main() {
    vec3 p = place(position);
    light = headlight(mat3(view) * normal, p);
    coord = colormap_coord(value);
#ifdef MISSING
    v_missing = missing;
#endif
}
