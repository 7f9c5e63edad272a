// The 1-D colormap texture (one row, clamp to edge; linear for smooth contours, nearest for
// bands) and the map from normalised value t to texture coordinate s = t * scale + offset.
// missing_color is the no-result colour (workbench.paths.colormap.NO_RESULT_COLOR): with
// MISSING defined the field has non-finite values, whose triangles arrive flagged (a flat
// no_result > 0.5, never interpolated) and are drawn in it, lit, opaque, whatever the
// transfer function says; their uploaded values are 0 and no sentinel is looked up.
uniform sampler2D colormap;
uniform vec2 colormap_st;
uniform vec3 missing_color;

float colormap_coord(float t) {
    return t * colormap_st.x + colormap_st.y;
}

// s clamped to [0, 1] first: the same texel as clamp-to-edge gives, but no coordinate far
// outside (llvmpipe's fixed-point texel addressing wraps one of 1e6 to a wrong texel)
vec4 colormap_lookup(float s) {
    return textureLod(colormap, vec2(clamp(s, 0.0, 1.0), 0.5), 0.0);
}
