//! Where emission draws its particles from.
//! Closed sets (`fluidform_gpu::kinds::Kind`): each parses and prints as its switch spells it.
use fluidform_gpu::switch_enum;

switch_enum!(EmitterKind { Uv, Vertices });
