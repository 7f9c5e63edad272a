#version 330
// quad_wire path: element outlines where a wire coordinate is close to 0 or 1.
// An edge shared by two elements is drawn within half a pixel on each side, an edge of one
// element only (bit set in boundary_bits) within one pixel on its side: one pixel either way.
uniform vec3 base_color;
uniform vec3 wire_color;
in float light;
in vec3 wire_coord;
flat in int boundary_bits;  // 1 u=0, 2 u=1, 4 v=0, 8 v=1, 16 w=0 alone; 32 a triangle
out vec4 frag_color;

float reach(int bit) {
    return (boundary_bits & bit) != 0 ? 1.0 : 0.5;
}

void main() {
    // change per pixel along the minor axis of each iso-line: like an aliased GL line, the
    // outline takes one pixel per step along its major axis, also at 45 degrees
    vec3 per_pixel = max(max(abs(dFdx(wire_coord)), abs(dFdy(wire_coord))), vec3(1e-6));
    vec3 to0 = wire_coord / per_pixel;          // pixels to the iso-line at 0
    vec3 to1 = (1.0 - wire_coord) / per_pixel;  // pixels to the iso-line at 1
    bool triangle = (boundary_bits & 32) != 0;
    // a little slack: an edge on a pixel boundary is drawn on both sides, never lost
    const float slack = 1e-3;
    bool on_edge = to0.x <= reach(1) + slack || to0.y <= reach(4) + slack
                || (triangle && to0.z <= reach(16) + slack)
                || (!triangle && (to1.x <= reach(2) + slack || to1.y <= reach(8) + slack));
    frag_color = vec4(on_edge ? wire_color : base_color * light, 1.0);
}
