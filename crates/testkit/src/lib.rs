//! Fixtures shared by the tests and benchmarks of the dualsplit crates, so that every
//! structure is held to one reference and every benchmark checks against the same answers
//! the tests do. It is a dev-dependency only (`publish = false`); no library depends on it.
//!
//! | module | what it gives |
//! |---|---|
//! | [`oracle`] | the brute-force closest hit and any hit; per-ray checks of all seven CPU traversals against them |
//! | [`dst`] | a BVH2 and its DST built together, and the per-ray check of both DST traversals |
//! | [`scenes`] | shipped meshes and a synthetic room built in code |
//! | [`rays`] | rays from the renderer's path-tracing jobs; random rays aimed at the edge cases |
//! | [`grazing`] | the grazing-ray regression cases of the slab test |
//!
//! Every comparison is per ray: the closest hit's `t` bits and triangle id, and the any-hit
//! answer, never a sum over rays.
//!
//! ```
//! use dualsplit_accel::{BuildConfig, Structures};
//! use dualsplit_geometry::{Ray, Triangle, Vec3};
//! use dualsplit_testkit::oracle::check_rays;
//!
//! let tris = [Triangle::new(
//!     Vec3::new(-1.0, -1.0, 1.0),
//!     Vec3::new(1.0, -1.0, 1.0),
//!     Vec3::new(0.0, 1.0, 1.0),
//! )];
//! let s = Structures::build(&tris, &BuildConfig::default());
//! check_rays(&s, &tris, &[Ray::new(Vec3::ZERO, Vec3::Z)]);
//! ```

pub mod dst;
pub mod grazing;
pub mod layout;
pub mod oracle;
pub mod rays;
pub mod scenes;
