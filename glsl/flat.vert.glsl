#version 330
// flat and element_color paths: the eye-space position feeds the derivative face normal
#include "common.vert.glsl"
in vec3 position;
out vec3 eye_position;

void main() {
    eye_position = place(position);
}
