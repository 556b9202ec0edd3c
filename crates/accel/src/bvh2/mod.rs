//! The encoded BVH2: 52-byte internal nodes holding both child boxes (Lin et al. 2020, §4.2).
//!
//! The logical tree is [`crate::Bvh2`] (built in [`crate::build`]); it is encoded through
//! [`crate::wide::WideBvh::from_bvh2`] and [`crate::wide::encode`] with the [`Node2`] layout and
//! traversed by the shared [`crate::wide::traverse`].

mod node;

pub use node::Node2;
