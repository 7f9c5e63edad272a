#version 330
in vec4 color;
out vec4 frag_color;

void main() {
#ifdef HIDE
    if (color.a < 0.5) discard;
#endif
    frag_color = vec4(color.rgb, 1.0);
}
