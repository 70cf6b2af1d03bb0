//! What the viewer reads and changes of a playing scene's targets: the timeline's events,
//! the newest control metrics, and the control switches that can change mid-run.
use super::SceneTargets;
use crate::control::target::ControlDesc;
use crate::error::Result;

impl SceneTargets {
    /// The control `overrides` (the switches') for every control target from the next frame on,
    /// when they change only values each frame uploads (c_cp, the adaptive thresholds and
    /// factors, velocity, attraction, damping). False, changing nothing, when any other
    /// would change (they shape pipelines or buffers: the scene must be rebuilt).
    pub fn set_control(
        &mut self,
        overrides: &crate::settings::ControlOverrides,
        fluid: &crate::sph::FluidParams,
    ) -> Result<bool> {
        let mut next = Vec::new();
        for l in &self.live {
            let (Some((c, _)), Some(d)) = (&l.control, &l.desc) else {
                continue;
            };
            let nd = overrides(d)?;
            let s = nd.settings(fluid);
            s.validate()?;
            let (o, od) = (&c.force.settings, &c.desc);
            let built = crate::control::force::ControlSettings {
                pressure: o.pressure,
                low: o.low,
                high: o.high,
                up: o.up,
                down: o.down,
                velocity: o.velocity,
                attraction: o.attraction,
                damping: o.damping,
                ..s.clone()
            };
            let desc = ControlDesc {
                pressure: od.pressure,
                thresholds: od.thresholds,
                factors: od.factors,
                velocity: od.velocity,
                attraction: od.attraction,
                damping: od.damping,
                preset: od.preset,
                ..nd.clone()
            };
            if built != *o || desc != *od {
                return Ok(false);
            }
            if nd.placement == crate::control::Placement::Rays
                && (s.velocity > 0.0 || s.damping > 0.0)
            {
                return Err(crate::Error::Param(
                    "--control-velocity and --control-damping need --placement vertices or random"
                        .into(),
                ));
            }
            next.push((nd, s));
        }
        let mut next = next.into_iter();
        for l in &mut self.live {
            if let (Some((c, _)), Some(_)) = (&mut l.control, &l.desc) {
                (c.desc, c.force.settings) = next.next().expect("one per control target");
            }
        }
        Ok(true)
    }

    /// The timeline's events as (time, what), for the viewer's list.
    pub fn events(&self) -> Vec<(f32, String)> {
        let t = self.timeline.events().iter();
        t.map(|e| (e.time, e.describe())).collect()
    }

    /// Each control target's newest metrics row (fill, iou, ...), for the viewer.
    pub fn latest_metrics(&self) -> Vec<crate::control::metrics::ControlRow> {
        let rows = self.controlled.iter().map(|&i| &self.live[i].control);
        rows.filter_map(|c| c.as_ref().and_then(|(_, m)| m.rows.last().cloned()))
            .collect()
    }
}
