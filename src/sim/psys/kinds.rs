//! The particle systems' choices: integrator and sprite mode.
//! Closed sets (`fluidform_gpu::kinds::Kind`): each parses and prints as its switch spells it.
use fluidform_gpu::switch_enum;

switch_enum!(Integrator {
    Euler,
    Verlet,
    Closed
});
switch_enum!(SpriteMode {
    Points,
    Streaks,
    Sprites
});
