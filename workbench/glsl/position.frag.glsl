#version 330
uniform vec3 base_color;
out vec4 frag_color;

void main() {
    frag_color = vec4(base_color, 1.0);
}
