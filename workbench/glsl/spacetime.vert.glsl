#version 330
// st2005 slice polygons (or, with BAR, the spacetime triangles of a 1-D bar in (x, t)).
// Height per vertex from the element polynomial; colour per vertex (PER_VERTEX) or handed to
// the fragment shader as the spacetime point and element slot (per pixel).
#include "spacetime_poly.glsl"
#include "spacetime_shade.glsl"
#include "spacetime_place.glsl"
in vec2 position;  // (x, y) or, for the bar, (x, t); relative to the upload origin
in int slot;
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
    gl_Position = place(world);
}
