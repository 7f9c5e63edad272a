#version 330
// flat path: the eye-space position feeds the derivative face normal
#include "common.vert.glsl"
in vec3 position;
out vec3 eye_position;

void main() {
    eye_position = place(position);
}
