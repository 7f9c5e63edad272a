#version 330
// a deleted element drawn translucent (Style.deleted = "ghost")
uniform vec4 ghost_color;
out vec4 frag_color;

void main() {
    frag_color = ghost_color;
}
