//! CPU twins of the pair terms in shaders/terms/ (registry: backend::terms), one
//! file each, same name, arguments and operation order as the WGSL function.

mod background_pressure;
mod barrier;
mod interface_viscosity;
mod marrone_viscosity;
mod pressure;
mod shepard_pressure;
mod solid_fluid_viscosity;
mod viscosity;
mod viscous_heating;

pub use background_pressure::background_pressure;
pub use barrier::barrier;
pub use interface_viscosity::{interface_viscosity, interface_viscosity_alpha};
pub use marrone_viscosity::marrone_viscosity;
pub use pressure::pressure;
pub use shepard_pressure::shepard_pressure;
pub use solid_fluid_viscosity::{solid_fluid_viscosity, solid_fluid_viscosity_alpha};
pub use viscosity::{pair_viscosity, viscosity};
pub use viscous_heating::viscous_heating;
