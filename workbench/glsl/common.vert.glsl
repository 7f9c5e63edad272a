// Shared by the render paths' vertex shaders: placement, clip planes (NUM_CLIP defined by the
// loader, 0..4; planes already moved to the upload origin in float64) and the headlight.
#include "headlight.glsl"
uniform mat4 mvp;
uniform mat4 view;
#if NUM_CLIP > 0
uniform vec4 clip_planes[NUM_CLIP];
out float gl_ClipDistance[NUM_CLIP];
#endif

// Sets gl_Position and the clip distances of a position relative to the upload origin;
// returns the eye-space position.
vec3 place(vec3 p) {
    gl_Position = mvp * vec4(p, 1.0);
#if NUM_CLIP > 0
    for (int i = 0; i < NUM_CLIP; ++i) {
        gl_ClipDistance[i] = dot(clip_planes[i].xyz, p) + clip_planes[i].w;
    }
#endif
    return (view * vec4(p, 1.0)).xyz;
}
