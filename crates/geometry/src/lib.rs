//! Geometry shared by every dualsplit structure: [`Aabb`], [`Ray`], [`Triangle`], the
//! watertight ray–triangle test (Woop, Benthin, Wald 2013), the NaN-permissive ray–slab
//! test, closest-hit ordering ([`Hit`]) and a deterministic PCG32 generator.
//!
//! ```
//! use dualsplit_geometry::{Ray, Triangle, Vec3};
//! let tri = Triangle::new(Vec3::new(-1.0, -1.0, 2.0), Vec3::new(1.0, -1.0, 2.0), Vec3::new(0.0, 1.0, 2.0));
//! let ray = Ray::new(Vec3::ZERO, Vec3::Z);
//! let hit = tri.intersect(&ray.precompute(), 0.0, f32::INFINITY).unwrap();
//! assert_eq!(hit.t, 2.0);
//! ```
//!
//! ## Robustness rules every traversal follows
//!
//! * Plane distances are always `(p - o[a]) * inv_dir[a]` with `inv_dir = 1 / dir` (IEEE:
//!   a zero component gives ±∞). When `p == o[a]` that is NaN; every min/max uses
//!   [`f32::min`]/[`f32::max`], which return the non-NaN operand, so a NaN plane never
//!   drops a child: the ray lies in that plane and is treated as inside the closed slab.
//! * Closest hits are ordered by `(t, prim)`: equal `t` goes to the smaller triangle id, so
//!   every structure returns the same triangle whatever its visiting order ([`Hit::closer_than`]).
//! * Culling against the best hit uses [`cull_limit`], a bound a little beyond the best `t`,
//!   so rounding differences between slab and triangle arithmetic never lose a tie.
//! * Exit-role plane distances are conservative (Ize 2013, "Robust BVH ray traversal",
//!   JCGT 2(2)): every distance that can end an interval (a far plane chosen by the ray's
//!   sign, a DST splitting node's `t1`, a carving plane acting as an exit) is multiplied by
//!   [`EXIT_WIDEN`] `= 1 + 2γ₃` ([`widen_exit`], [`RayPre::exit_t`]); entry distances are
//!   not. A ray aimed exactly at a triangle vertex that is also a box corner then still
//!   enters the box, as the watertight triangle test accepts the hit. Every structure
//!   widens the same distances with the same single multiplication, and widening commutes
//!   with `min`, so all structures still reach the same leaves and return bit-identical hits.
//!   (The CPU-side copies of the BVH images, which plain queries traverse, fold the factor
//!   into the reciprocal instead; their exits may differ in the last bit, which changes no
//!   answer: `dualsplit_accel::wide::cpu`.)

mod aabb;
pub mod fmath;
mod hit;
mod ray;
mod rng;
mod triangle;

pub use aabb::Aabb;
pub use glam::Vec3;
pub use hit::{Hit, PrimId, cull_limit};
pub use ray::{EXIT_WIDEN, Ray, RayPre, gamma, widen_exit};
pub use rng::{Pcg32, hash_u32s};
pub use triangle::{Triangle, TriangleHit};
