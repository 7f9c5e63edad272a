// Clip position of a world point (relative to the upload origin). With DEPTH_HALF the depth is
// squeezed into the near (-1) or far (+1) half of the range, so that what is drawn in the far
// half shows only where nothing of the near half covers the pixel; the near and far planes
// then clip through clip distances, as the squeezed depth no longer does.
uniform mat4 mvp;

vec4 place(vec3 world) {
    vec4 p = mvp * vec4(world, 1.0);
#ifdef DEPTH_HALF
    gl_ClipDistance[0] = p.w + p.z;
    gl_ClipDistance[1] = p.w - p.z;
    p.z = 0.5 * p.z + 0.5 * float(DEPTH_HALF) * p.w;
#endif
    return p;
}
