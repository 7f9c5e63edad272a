// st2005 colour and lighting, the float32 twin of workbench.algo.spacetime.shading.
uniform sampler2D ramp;       // 256 x 1 RGBA8, linear filtering, entry i at s = i/255
uniform float log_denominator; // log(U_max + 1)
uniform float height_scale;    // mm of height per mm/us of speed
uniform vec3 light;            // unit direction towards the light, world
uniform float lighting;        // 1: Phong with the exact height-field normal, 0: ramp colour only
const float AMBIENT = 0.3, DIFFUSE = 0.6, SPECULAR = 0.25, SHININESS = 16.0;

vec3 ramp_color(float U) {
    float s = clamp(log(max(U, 0.0) + 1.0) / log_denominator, 0.0, 1.0);
    return texture(ramp, vec2(s * (255.0 / 256.0) + 0.5 / 256.0, 0.5)).rgb;
}

vec3 shade(Solution s, vec3 eye_dir) {
    vec3 c = ramp_color(s.U);
    if (lighting < 0.5) return c;
    vec3 n = normalize(vec3(-height_scale * s.grad_speed, 1.0));
    float nl = dot(n, light);
    vec3 r = 2.0 * nl * n - light;
    float spec = pow(max(dot(r, eye_dir), 0.0), SHININESS);
    return clamp(c * (AMBIENT + DIFFUSE * max(nl, 0.0) + SPECULAR * spec), 0.0, 1.0);
}
