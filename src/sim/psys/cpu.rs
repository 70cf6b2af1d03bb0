//! CPU references for the particle-system tests: the closed form, the attractor's
//! potential (for energy), and what the GPU's counters and lists must satisfy.
use glam::Vec3;

/// p0 + v0 t + g t^2 / 2.
pub fn closed_pos(p0: Vec3, v0: Vec3, g: Vec3, t: f32) -> Vec3 {
    p0 + v0 * t + 0.5 * g * t * t
}

/// Potential energy per unit mass of the attractor strength / (r^2 + eps) at distance r:
/// U(r) = (s / sqrt(eps)) atan(r / sqrt(eps)): the pull -dU/dr = -s / (r^2 + eps).
pub fn attractor_potential(r: f32, strength: f32, eps: f32) -> f64 {
    let e = (eps as f64).sqrt();
    (strength as f64 / e) * (r as f64 / e).atan()
}

/// Whether the alive and dead lists partition 0..capacity: each slot in exactly one.
pub fn partitions(alive: &[u32], dead: &[u32], capacity: u32) -> Result<(), String> {
    let mut seen = vec![0u8; capacity as usize];
    for &s in alive.iter().chain(dead) {
        let Some(c) = seen.get_mut(s as usize) else {
            return Err(format!("slot {s} out of range"));
        };
        *c += 1;
    }
    match seen.iter().position(|&c| c != 1) {
        Some(i) => Err(format!("slot {i} appears {} times", seen[i])),
        None => Ok(()),
    }
}
