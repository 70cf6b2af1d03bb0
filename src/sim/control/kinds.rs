//! The control particles' choices: placement, adaptive pressure, presets, motion, deficit, bone weights.
//! Closed sets (`fluidform_gpu::kinds::Kind`): each parses and prints as its switch spells it.
use fluidform_gpu::switch_enum;

switch_enum!(Placement {
    Vertices,
    Random,
    Rays
});
switch_enum!(Adaptive { Off, On, Smooth });
switch_enum!(ControlPreset { Thesis, Fidelity });
switch_enum!(ControlMotion { Frames, Skin });
switch_enum!(Deficit { Rest, Shape });
switch_enum!(BoneWeights { Eq8, Eq9, Skin });
