#version 330
uniform vec3 base_color;
in float light;
out vec4 frag_color;

void main() {
    frag_color = vec4(base_color * light, 1.0);
}
