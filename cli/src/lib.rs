//! The projfluid lab: what the `projfluid` command line is made of, above the solver core
//! ([`projfluid`]): the run driver and run summaries, reading frames back, the solver
//! benchmark, ρ tuning, the validation against experiments and the hydrostatic tank, charts,
//! tables and the PNG renderer. Nothing here is needed to embed the solver.

pub mod bench;
pub mod driver;
pub mod frames;
pub mod plot;
pub mod render;
pub mod summary;
pub mod table;
pub mod tuning;
pub mod validation;
