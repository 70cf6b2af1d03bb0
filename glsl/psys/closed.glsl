// The stateless closed form p(t) = p0 + v0 t + g t^2 / 2 (seed 003).
#ifndef PSYS_CLOSED_GLSL
#define PSYS_CLOSED_GLSL
vec3 closed_pos(vec3 p0, vec3 v0, vec3 g, float t) { return p0 + v0 * t + 0.5 * g * t * t; }
#endif
