#version 330
// st2005 edge skirts: every shared polygon edge, a line of two slice vertices, becomes a
// vertical quad hanging from the edge down to skirt_floor (below every height). Drawn in the
// far half of the depth range behind the polygons, a skirt shows only through a gap: between
// two elements whose heights differ, the opening lies under the higher edge, in the vertical
// plane of the edge, so the higher side's skirt covers it however wide it is. The top
// vertices are the vertex shader's own, so a skirt meets its polygon without a pinhole.
#include "spacetime_place.glsl"
layout(lines) in;
layout(triangle_strip, max_vertices = 4) out;
uniform float skirt_floor;  // world z (mm, relative), below every height drawn
flat in int v_slot[];
in vec3 v_st[];
in vec3 v_world[];
flat out int g_slot;
out vec3 g_st;
out vec3 g_world;
#ifdef PER_VERTEX
in vec3 v_color[];
out vec3 g_color;
#endif

void emit(int i, bool dropped) {
    g_slot = v_slot[i];
    g_st = v_st[i];
#ifdef PER_VERTEX
    g_color = v_color[i];
#endif
    if (dropped) {
        g_world = vec3(v_world[i].xy, skirt_floor);
        gl_Position = place(g_world);
    } else {
        g_world = v_world[i];
        gl_Position = gl_in[i].gl_Position;
#ifdef DEPTH_HALF
        gl_ClipDistance[0] = gl_in[i].gl_ClipDistance[0];
        gl_ClipDistance[1] = gl_in[i].gl_ClipDistance[1];
#endif
    }
    EmitVertex();
}

void main() {
    emit(0, false);
    emit(1, false);
    emit(0, true);
    emit(1, true);
    EndPrimitive();
}
