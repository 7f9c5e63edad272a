#version 330
// fe2003 texture paths: placement, the atlas coordinate, and either the per-vertex (Gouraud)
// headlight of the original mesh (NORMAL_MAP 0) or what the fragment shader needs to light
// with the normal map (NORMAL_MAP 1): the eye-space position and the dropped normal axis.
#include "common.vert.glsl"
in vec3 position;
in vec2 texcoord;  // uv / (W, H)
out vec2 st;
#if WIRE_CORNERS
in int base;  // the row of the subpatch's first element in the corner table
flat out int element_base;
#endif
#if NORMAL_MAP
in float axis;  // dropped normal component 0, 1 or 2, constant over a subpatch
out vec3 eye_position;
flat out int normal_axis;
#else
in vec3 normal;
out float light;
#endif

void main() {
    vec3 p = place(position);
    st = texcoord;
#if WIRE_CORNERS
    element_base = base;
#endif
#if NORMAL_MAP
    eye_position = p;
    normal_axis = int(axis + 0.5);
#else
    light = headlight(mat3(view) * normal, p);
#endif
}
