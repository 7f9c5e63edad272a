#version 330
#include "headlight.glsl"
uniform vec3 base_color;
in vec3 eye_position;
out vec4 frag_color;

void main() {
    // face normal from the screen-space derivatives of the eye-space position
    vec3 n = cross(dFdx(eye_position), dFdy(eye_position));
    frag_color = vec4(base_color * headlight(n, eye_position), 1.0);
}
