#version 330
// The no-result rule of the per-vertex field paths (MISSING defined): each triangle passed on
// unchanged, with one flat flag, no_result = the largest of its vertices' missing flags (0 or
// 1, exact), so a triangle with any vertex whose node has no finite value is drawn whole in
// the no-result colour and no interpolated number decides it. VERTEX_COLOR: the lit colour and
// the light of vertex_color; otherwise the light and texture coordinate of pixel_color.
// Clip distances (NUM_CLIP, 0..4) are passed on as the vertex shader wrote them.
layout(triangles) in;
layout(triangle_strip, max_vertices = 3) out;
#if NUM_CLIP > 0
out float gl_ClipDistance[NUM_CLIP];
#endif
in float v_missing[];
in float v_light[];
out float light;
flat out float no_result;
#ifdef VERTEX_COLOR
in vec4 v_color[];
out vec4 color;
#else
in float v_coord[];
out float coord;
#endif

void main() {
    float flag = max(max(v_missing[0], v_missing[1]), v_missing[2]);
    for (int i = 0; i < 3; ++i) {
        gl_Position = gl_in[i].gl_Position;
        // constant indices: gl_in's clip distances are not sized here (at most 4 planes)
#if NUM_CLIP > 0
        gl_ClipDistance[0] = gl_in[i].gl_ClipDistance[0];
#endif
#if NUM_CLIP > 1
        gl_ClipDistance[1] = gl_in[i].gl_ClipDistance[1];
#endif
#if NUM_CLIP > 2
        gl_ClipDistance[2] = gl_in[i].gl_ClipDistance[2];
#endif
#if NUM_CLIP > 3
        gl_ClipDistance[3] = gl_in[i].gl_ClipDistance[3];
#endif
        light = v_light[i];
#ifdef VERTEX_COLOR
        color = v_color[i];
#else
        coord = v_coord[i];
#endif
        no_result = flag;
        EmitVertex();
    }
    EndPrimitive();
}
