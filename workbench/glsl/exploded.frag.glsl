#version 330
// exploded path: flat shading (derivative face normal) with an opacity for the ghosted half
#include "headlight.glsl"
uniform vec3 base_color;
uniform float alpha;
in vec3 eye_position;
out vec4 frag_color;

void main() {
    vec3 n = cross(dFdx(eye_position), dFdy(eye_position));
    frag_color = vec4(base_color * headlight(n, eye_position), alpha);
}
