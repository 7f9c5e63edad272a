#version 330
// st2005 slice polygons (or, with BAR, the spacetime triangles of a 1-D bar in (x, t)).
// Height per vertex from the element polynomial; colour per vertex (PER_VERTEX) or handed to
// the fragment shader as the spacetime point and element slot (per pixel).
#include "spacetime_poly.glsl"
#include "spacetime_shade.glsl"
in vec2 position;  // (x, y) or, for the bar, (x, t); relative to the upload origin
in int slot;
uniform mat4 mvp;
uniform float t_slice;     // slice time, us (time is never shifted)
uniform vec3 eye_position; // relative world position of the eye (perspective)
uniform vec3 eye_axis;     // unit direction towards the eye (orthographic)
uniform float perspective;
flat out int v_slot;
out vec3 v_st;
out vec3 v_world;
#ifdef PER_VERTEX
out vec3 v_color;
#endif

void main() {
#ifdef BAR
    vec3 st = vec3(position.x, 0.0, position.y);
    Solution s = evaluate(slot, st);
    vec3 world = vec3(position, 0.0);
#else
    vec3 st = vec3(position, t_slice);
    Solution s = evaluate(slot, st);
    vec3 world = vec3(position, height_scale * s.speed);
#endif
    v_slot = slot;
    v_st = st;
    v_world = world;
#ifdef PER_VERTEX
    vec3 eye_dir = perspective > 0.5 ? normalize(eye_position - world) : eye_axis;
    v_color = shade(s, eye_dir);
#endif
    gl_Position = mvp * vec4(world, 1.0);
#ifdef DEPTH_HALF
    // edge overdraw behind the fill: polygons (DEPTH_HALF -1) in the near half of the depth
    // range, lines (+1) in the far half, so lines fill only what no polygon covers; the near
    // and far planes then clip through clip distances, as the squeezed depth no longer does
    gl_ClipDistance[0] = gl_Position.w + gl_Position.z;
    gl_ClipDistance[1] = gl_Position.w - gl_Position.z;
    gl_Position.z = 0.5 * gl_Position.z + 0.5 * float(DEPTH_HALF) * gl_Position.w;
#endif
}
