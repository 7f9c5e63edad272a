#version 330
#include "spacetime_poly.glsl"
#include "spacetime_shade.glsl"
#ifdef SKIRT  // the inputs come from the skirt geometry shader
#define v_slot g_slot
#define v_st g_st
#define v_world g_world
#define v_color g_color
#endif
uniform vec3 eye_position;
uniform vec3 eye_axis;
uniform float perspective;
flat in int v_slot;
in vec3 v_st;
in vec3 v_world;
#ifdef PER_VERTEX
in vec3 v_color;
#endif
out vec4 frag_color;

void main() {
#ifdef PER_VERTEX
    frag_color = vec4(v_color, 1.0);
#else
    vec3 eye_dir = perspective > 0.5 ? normalize(eye_position - v_world) : eye_axis;
    frag_color = vec4(shade(evaluate(v_slot, v_st), eye_dir), 1.0);
#endif
}
