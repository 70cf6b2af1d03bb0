//! The checks of a `[[system]]` table: every value in range, a clear message naming the
//! system and the key.
// Checks are written `!(x > 0.0)` on purpose: NaN fails them.
#![allow(clippy::neg_cmp_op_on_partial_ord)]
use super::*;
use crate::error::{Error, Result};

fn finite(v: &[f32]) -> bool {
    v.iter().all(|x| x.is_finite())
}

impl SystemSpec {
    /// Every value in range; the closed form only with forces that have one.
    pub fn validate(&self) -> Result<()> {
        if self.capacity == 0 || self.capacity > 1 << 26 {
            return self.bad(format!("capacity {} is not in 1..=67108864", self.capacity));
        }
        self.check_emitter()?;
        self.check_particle()?;
        self.check_over_life()?;
        self.check_forces_and_colliders()?;
        self.check_death_and_events()?;
        if self.emitter.burst > self.capacity {
            return self.bad(format!(
                "emitter: a burst of {} exceeds the capacity",
                self.emitter.burst
            ));
        }
        self.check_boids()?;
        self.check_closed_form()?;
        if !(self.point_px >= 1.0 && self.point_px <= 64.0) {
            return self.bad("point_px must be in [1, 64]".into());
        }
        if self.draw() == SpriteMode::Points && matches!(self.sort, Some(s) if s != SortAlgo::None)
        {
            return self.bad("points are opaque and depth-tested: they take no sort".into());
        }
        Ok(())
    }

    /// The parameter error naming this system.
    fn bad(&self, m: String) -> Result<()> {
        Err(Error::Param(format!("system '{}': {}", self.name, m)))
    }

    /// The emission rate and the emitter shape.
    fn check_emitter(&self) -> Result<()> {
        let e = &self.emitter;
        match (&e.rate, e.per_area) {
            (Some(r), None)
                if r.mean >= 0.0 && r.variance >= 0.0 && finite(&[r.mean, r.variance]) => {}
            (None, Some(a)) if a > 0.0 && a.is_finite() => {}
            (Some(_), Some(_)) => {
                return self.bad("emitter: give rate or per_area, not both".into())
            }
            (None, None) if e.burst > 0 => {}
            (None, None) => {
                return self.bad("emitter: give rate = {mean, variance}, per_area or burst".into())
            }
            _ => return self.bad("emitter: the rate must be finite and not negative".into()),
        }
        if matches!(e.shape, Shape::Sphere | Shape::Disc) && !(e.radius > 0.0) {
            return self
                .bad(format!("emitter: a {:?} needs a positive radius", e.shape).to_lowercase());
        }
        if e.shape == Shape::Disc && !(glam::Vec3::from(e.normal).length() > 1e-6) {
            return self.bad("emitter: the disc normal is zero".into());
        }
        if e.shape == Shape::Box && e.half.iter().any(|h| !(*h >= 0.0)) {
            return self.bad("emitter: box half extents must not be negative".into());
        }
        if let Some([r, period]) = e.orbit {
            if !(r >= 0.0 && period > 0.0) {
                return self.bad("emitter: orbit = [radius >= 0, period > 0]".into());
            }
        }
        Ok(())
    }

    /// The new particles' attributes, gravity, wind and damping.
    fn check_particle(&self) -> Result<()> {
        let p = &self.particle;
        if !(p.life.mean > 0.0) || p.life.variance < 0.0 || p.life.variance >= p.life.mean {
            return self
                .bad("particle.life: mean must be positive and variance in [0, mean)".into());
        }
        if !(0.0..=180.0).contains(&p.spread) {
            return self.bad("particle.spread must be in [0, 180] degrees".into());
        }
        if p.size.mean < 0.0 || p.size.variance < 0.0 {
            return self.bad("particle.size: mean and variance must not be negative".into());
        }
        let nums: Vec<f32> = [
            p.offset.mean,
            p.offset.variance,
            p.velocity.mean,
            p.velocity.variance,
        ]
        .iter()
        .flatten()
        .chain(p.color.mean.iter())
        .chain(p.color.variance.iter())
        .chain(self.gravity.iter())
        .chain(self.wind.iter())
        .copied()
        .collect();
        if !finite(&nums) || !self.damping.is_finite() || self.damping < 0.0 || self.wind[3] < 0.0 {
            return self.bad(
                "attributes, gravity, wind and damping must be finite (damping and drag >= 0)"
                    .into(),
            );
        }
        Ok(())
    }

    /// Key times over life rise within [0, 1].
    fn check_over_life(&self) -> Result<()> {
        let o = &self.over_life;
        for (what, ts) in [
            ("size", o.size.iter().map(|k| k[0]).collect::<Vec<_>>()),
            ("color", o.color.iter().map(|k| k[0]).collect()),
            ("opacity", o.opacity.iter().map(|k| k[0]).collect()),
        ] {
            if ts.len() > MAX_KEYS {
                return self.bad(format!("over_life.{what}: at most {MAX_KEYS} keys"));
            }
            if ts.windows(2).any(|w| !(w[0] < w[1])) || ts.iter().any(|t| !(0.0..=1.0).contains(t))
            {
                return self.bad(format!(
                    "over_life.{what}: key times must rise within [0, 1]"
                ));
            }
        }
        Ok(())
    }

    /// Force fields and colliders: counts and values.
    fn check_forces_and_colliders(&self) -> Result<()> {
        if self.force.len() > MAX_FORCES || self.collider.len() > MAX_COLLIDERS {
            return self.bad(format!(
                "at most {MAX_FORCES} forces and {MAX_COLLIDERS} colliders"
            ));
        }
        for f in &self.force {
            if !f.strength.is_finite() || !(f.eps > 0.0) || !(f.scale > 0.0) {
                return self.bad(
                    format!(
                        "force {:?}: strength finite, eps and scale positive",
                        f.kind
                    )
                    .to_lowercase(),
                );
            }
        }
        for c in &self.collider {
            let ok = match c.kind {
                ColliderKind::Plane => glam::Vec3::from(c.normal).length() > 1e-6,
                ColliderKind::Sphere => c.radius > 0.0,
                ColliderKind::Box => (0..3).all(|k| c.min[k] < c.max[k]),
                ColliderKind::Capsule => c.radius > 0.0,
                ColliderKind::Character => true,
            };
            if !ok {
                return self.bad(format!("collider {:?}: a plane needs a normal, a sphere or capsule a radius, a box min < max", c.kind).to_lowercase());
            }
            if !(0.0..=1.0).contains(&c.restitution) || !(0.0..=1.0).contains(&c.friction) {
                return self.bad("collider: restitution and friction must be in [0, 1]".into());
            }
        }
        Ok(())
    }

    /// Death by distance and the events that spawn children.
    fn check_death_and_events(&self) -> Result<()> {
        if let Some(d) = self.death.max_distance {
            if !(d > 0.0) {
                return self.bad("death.max_distance must be positive".into());
            }
        }
        for (k, ev) in self.event.iter().enumerate() {
            let c = ev.count;
            if !(c.mean >= 0.0 && c.variance >= 0.0 && c.mean + c.variance <= MAX_CHILDREN) {
                return self.bad(format!(
                    "event on {:?}: count mean and variance >= 0, mean + variance <= {MAX_CHILDREN}",
                    ev.on
                )
                .to_lowercase());
            }
            if !ev.inherit.is_finite() {
                return self.bad("event: inherit must be finite".into());
            }
            if self.event[..k].iter().any(|o| o.on == ev.on) {
                return self.bad(format!("two events on {:?}", ev.on).to_lowercase());
            }
            if ev.on == EventKind::Collision && self.collider.is_empty() {
                return self.bad("an event on collision needs a [[system.collider]]".into());
            }
            if ev.on == EventKind::Death && ev.keep_parent {
                return self.bad("keep_parent applies to collision events only".into());
            }
        }
        Ok(())
    }

    /// Boids' radii, speeds, weights and bounds.
    fn check_boids(&self) -> Result<()> {
        if let Some(b) = &self.boids {
            let pos = [
                b.radius,
                b.separation_radius,
                b.max_speed,
                b.max_steer,
                b.look_ahead,
            ];
            let weights = [
                b.separation,
                b.alignment,
                b.cohesion,
                b.avoidance,
                b.min_speed,
            ];
            if !pos.iter().all(|x| *x > 0.0 && x.is_finite())
                || !weights.iter().all(|x| *x >= 0.0 && x.is_finite())
            {
                return self.bad("boids: radii, max_speed, max_steer and look_ahead positive; weights and min_speed >= 0".into());
            }
            if b.separation_radius > b.radius || b.min_speed > b.max_speed {
                return self
                    .bad("boids: separation_radius <= radius and min_speed <= max_speed".into());
            }
            crate::primitives::neighbors::GridSpec::covering(b.bounds[0], b.bounds[1], b.radius)
                .map_err(|e| Error::Param(format!("system '{}': boids bounds: {e}", self.name)))?;
            if !(0..3).all(|k| b.bounds[0][k] < b.bounds[1][k]) {
                return self.bad("boids: bounds = [min, max] with min < max".into());
            }
        }
        Ok(())
    }

    /// The closed form only without state: no forces, colliders, drag, events, boids.
    fn check_closed_form(&self) -> Result<()> {
        if self.integrator() == Integrator::Closed {
            let stateful = |what: &str| {
                Err(Error::Unsupported(format!(
                    "system '{}': --integrator closed evaluates p0 + v0 t + g t^2 / 2 with no state: {what} has no closed form here (use euler or verlet)",
                    self.name
                )))
            };
            if !self.force.is_empty() {
                return stateful("a force");
            }
            if !self.collider.is_empty() {
                return stateful("a collider");
            }
            if self.wind[3] != 0.0 || self.damping != 0.0 {
                return stateful("wind drag or damping");
            }
            if !self.event.is_empty() {
                return stateful("an event (collision or death)");
            }
            if self.boids.is_some() {
                return stateful("boids' steering");
            }
            if self.death.max_distance.is_some() || self.death.out_of_view {
                return stateful("death by distance or view (a state change)");
            }
        }
        Ok(())
    }
}
