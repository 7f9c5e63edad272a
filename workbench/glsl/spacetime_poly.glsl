// st2005 per-element cubic displacement polynomials, evaluated in element-local coordinates.
// Element data: ELEMENT_TEXELS float RGBA texels per element, texel 0 = centre (x, y, t)
// relative to the upload origin, texel 1 = 1/extent, texels 2..11 = the 20 coefficient vectors
// c_a = (u_x, u_y), two per texel, in the order
// 1, x, y, t, x2, xy, xt, y2, yt, t2, x3, x2y, x2t, xy2, xyt, xt2, y3, y2t, yt2, t3.
// With ELEMENT_BUFFER they sit in a buffer texture indexed by slot (texel slot*12 + k);
// otherwise in a 2-D texture, rows of ELEMENTS_PER_ROW elements never broken across rows,
// like the paper's texture rectangle.
#define ELEMENT_TEXELS 12
#define ELEMENTS_PER_ROW 341
#ifdef ELEMENT_BUFFER
uniform samplerBuffer elements;
#else
uniform sampler2D elements;
#endif
uniform float lam_k;  // Lame constants in kJ/m3 per unit strain squared (GPa * 1e6)
uniform float mu_k;

struct Solution {
    float U;          // strain energy density, kJ/m3
    float speed;      // |v|, mm/us
    vec2 grad_speed;  // spatial gradient of |v|, 1/us
};

vec4 element_texel(int slot, int k) {
#ifdef ELEMENT_BUFFER
    return texelFetch(elements, slot * ELEMENT_TEXELS + k);
#else
    int row = slot / ELEMENTS_PER_ROW;
    int col = (slot - row * ELEMENTS_PER_ROW) * ELEMENT_TEXELS + k;
    return texelFetch(elements, ivec2(col, row), 0);
#endif
}

Solution evaluate(int slot, vec3 st) {
    vec3 centre = element_texel(slot, 0).xyz;
    vec3 inv = element_texel(slot, 1).xyz;
    vec3 p = (st - centre) * inv;
    float x = p.x, y = p.y, t = p.z;
    // derivatives of the 20 monomials: d/dx, d/dy, d/dt, d2/dxdt, d2/dydt (local coordinates)
    float dx[20] = float[20](0., 1., 0., 0., 2.*x, y, t, 0., 0., 0.,
                             3.*x*x, 2.*x*y, 2.*x*t, y*y, y*t, t*t, 0., 0., 0., 0.);
    float dy[20] = float[20](0., 0., 1., 0., 0., x, 0., 2.*y, t, 0.,
                             0., x*x, 0., 2.*x*y, x*t, 0., 3.*y*y, 2.*y*t, t*t, 0.);
    float dt[20] = float[20](0., 0., 0., 1., 0., 0., x, 0., y, 2.*t,
                             0., 0., x*x, 0., x*y, 2.*x*t, 0., y*y, 2.*y*t, 3.*t*t);
    float dxt[20] = float[20](0., 0., 0., 0., 0., 0., 1., 0., 0., 0.,
                              0., 0., 2.*x, 0., y, 2.*t, 0., 0., 0., 0.);
    float dyt[20] = float[20](0., 0., 0., 0., 0., 0., 0., 0., 1., 0.,
                              0., 0., 0., 0., x, 0., 0., 2.*y, 2.*t, 0.);
    vec2 gx = vec2(0.0), gy = vec2(0.0), v = vec2(0.0), vx = vec2(0.0), vy = vec2(0.0);
    for (int k = 0; k < 10; ++k) {
        vec4 c = element_texel(slot, 2 + k);
        int a = 2 * k, b = 2 * k + 1;
        gx += c.xy * dx[a] + c.zw * dx[b];
        gy += c.xy * dy[a] + c.zw * dy[b];
        v += c.xy * dt[a] + c.zw * dt[b];
        vx += c.xy * dxt[a] + c.zw * dxt[b];
        vy += c.xy * dyt[a] + c.zw * dyt[b];
    }
    gx *= inv.x; gy *= inv.y; v *= inv.z; vx *= inv.x * inv.z; vy *= inv.y * inv.z;
    float exx = gx.x, eyy = gy.y, exy = 0.5 * (gx.y + gy.x);
    Solution s;
    s.U = 0.5 * (lam_k * (exx + eyy) * (exx + eyy) + 2.0 * mu_k * (exx * exx + eyy * eyy + 2.0 * exy * exy));
    s.speed = length(v);
    s.grad_speed = s.speed > 0.0 ? vec2(dot(v, vx), dot(v, vy)) / s.speed : vec2(0.0);
    return s;
}
