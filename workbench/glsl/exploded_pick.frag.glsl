#version 330
// exploded path, colour picking: the drawn part's code (index + 1, 24 bits) in RGB, unlit
uniform vec3 pick_color;
in vec3 eye_position;
out vec4 frag_color;

void main() {
    frag_color = vec4(pick_color, 1.0);
}
