//! The control passes as declarations, with the key they are built with.
use super::interface::ControlIo;
use super::settings::ControlSettings;
use crate::gpu::pass::{Defines, PassKey};
use crate::primitives::neighbors::NbKey;

/// The control passes' variant: the fluid's neighbour search (they walk its grid) with
/// the fluid's constants, and the adaptive pressure mode.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ControlKey {
    pub search: NbKey,
    pub adaptive: crate::control::Adaptive,
}

impl PassKey for ControlKey {
    fn all() -> Vec<Self> {
        let modes = crate::control::Adaptive::all();
        let each = |search: NbKey| modes.iter().map(move |a| (search, *a));
        NbKey::all()
            .into_iter()
            .flat_map(each)
            .map(|(search, adaptive)| Self { search, adaptive })
            .collect()
    }
    fn defines(&self) -> Defines {
        let mut d = self.search.defines();
        d.extend(crate::sph::params::defines());
        let own = ControlSettings::defines(self.adaptive).into_iter();
        d.extend(own.map(|(k, v)| (k.to_string(), v)));
        d
    }
}

crate::gpu::compute_pass!(pub CONTROL_DENSITY: ControlIo, ControlKey = "control-density", "control/density.comp");
crate::gpu::compute_pass!(pub CONTROL_AGGREGATE: ControlIo, ControlKey = "control-aggregate", "control/aggregate.comp");
crate::gpu::compute_pass!(pub CONTROL_FIELD: ControlIo, ControlKey = "control-field", "control/field.comp");
crate::gpu::compute_pass!(
    /// The force, its neighbours' terms refreshed.
    pub CONTROL_FORCE: ControlIo, ControlKey = "control-force", "control/force.comp", "CONTROL_REFRESH" = "1"
);
crate::gpu::compute_pass!(
    /// The force from the terms the last refresh stored.
    pub CONTROL_FORCE_STORED: ControlIo, ControlKey = "control-force-stored", "control/force.comp", "CONTROL_REFRESH" = "0"
);
