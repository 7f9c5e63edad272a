#version 330
// the drawn triangle's position in the draw call, plus one (0: nothing drawn), for sort-last
// compositing of GL domains
out uint triangle_id;

void main() {
    triangle_id = uint(gl_PrimitiveID) + 1u;
}
