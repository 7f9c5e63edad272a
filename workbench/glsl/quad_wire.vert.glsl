#version 330
// quad_wire path: Gouraud lighting plus the per-strip wire coordinate and boundary bits
#include "common.vert.glsl"
in vec3 position;
in vec3 normal;
in vec3 wire;
in float boundary;
out float light;
out vec3 wire_coord;
flat out int boundary_bits;

void main() {
    vec3 p = place(position);
    light = headlight(mat3(view) * normal, p);
    wire_coord = wire;
    boundary_bits = int(boundary + 0.5);
}
