#version 330
// gouraud path: per-vertex lighting with the crease-split vertex normals
#include "common.vert.glsl"
in vec3 position;
in vec3 normal;
out float light;

void main() {
    vec3 p = place(position);
    light = headlight(mat3(view) * normal, p);
}
