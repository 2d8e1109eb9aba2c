//! projfluid: liquids as SPH particles simulated with Projective Dynamics (Weiler et al. 2016),
//! accelerated with Chebyshev's semi-iterative method (Sommer et al. 2020).
//!
//! A [`World`] holds fluid and boundary particles and advances them in time:
//!
//! ```
//! use projfluid::{Params, World, Vec3, boundary::Aabb};
//! let mut world = World::new(Params::default()).unwrap();
//! world.add_container(Aabb { min: Vec3::zeros(), max: Vec3::new(0.6, 0.6, 0.6) }, 1).unwrap();
//! world.add_fluid_block(Vec3::repeat(0.05), [4, 4, 4], Vec3::zeros()).unwrap();
//! world.advance(0.01).unwrap();
//! assert_eq!(world.escaped_count(), 0);
//! ```
//!
//! Units are SI throughout: metres, seconds, kilograms.

pub mod body;
pub mod boundary;
pub mod checkpoint;
pub mod constraint;
pub mod emitter;
mod error;
pub mod ffi;
mod fluid;
mod forces;
#[cfg(feature = "gpu")]
mod gpu;
pub mod io;
pub mod kernel;
pub mod material;
pub mod neighbors;
pub mod params;
mod permutation;
pub mod pressure;
pub mod probe;
mod random;
pub mod reduce;
mod reserve;
pub mod scene;
mod simd;
pub mod solver;
pub mod stats;
mod step;
mod world;

pub use emitter::{Emitter, EmitterShape, EmitterSpec, EmitterState};
pub use error::Error;
pub use material::{Material, MaterialId};
pub use params::{ChebyshevParams, Omega2Rule, Params, ProjectionWeight, SolverKind};
#[cfg(feature = "gpu")]
pub use world::GpuPositions;
pub use world::{Backend, BodyId, EmitterId, GridParts, SinkId, World, WorldState};

/// A 3-vector of f64 (metres, metres per second, …).
pub type Vec3 = nalgebra::Vector3<f64>;

/// The README's Rust quick start, compiled and run as written by the doctests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeQuickStart;
