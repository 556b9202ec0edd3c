//! The compressed 8-wide BVH (Ylitie, Karras and Laine 2017): 80-byte nodes with 8-bit
//! quantized child boxes, made from the BVH8 (identical partitioning).
//! INTEGRATION STUB: replaced by the real module on merge.

use crate::Bvh2;
use crate::image::{ImageError, MemoryImage, SharedTriangles};
use crate::observer::Observer;
use crate::validate::ValidationReport;
use crate::wide::WideBvh;
use dualsplit_geometry::{Hit, Ray};
use std::time::Duration;

/// Stub.
#[derive(Clone, Debug)]
pub struct Cwbvh {
    image: MemoryImage,
}

impl Cwbvh {
    /// Stub.
    pub fn from_wide(
        _wide: &WideBvh,
        _bvh: &Bvh2,
        _triangles: impl Into<SharedTriangles>,
        _time: Duration,
    ) -> Result<Self, ImageError> {
        todo!()
    }
    /// Stub.
    pub fn with_time(self, _time: Duration) -> Self {
        todo!()
    }
    /// Stub.
    pub fn from_image(_image: MemoryImage) -> Result<Self, ValidationReport> {
        todo!()
    }
    /// Stub.
    pub fn from_parts(_image: MemoryImage, _internal_nodes: usize, _leaves: usize) -> Self {
        todo!()
    }
    /// Stub.
    pub fn image(&self) -> &MemoryImage {
        &self.image
    }
    /// Stub.
    pub fn internal_nodes(&self) -> usize {
        todo!()
    }
    /// Stub.
    pub fn leaves(&self) -> usize {
        todo!()
    }
    /// Stub.
    pub fn time(&self) -> Duration {
        todo!()
    }
    /// Stub.
    pub fn bytes_total(&self) -> u64 {
        todo!()
    }
    /// Stub.
    pub fn closest_hit<O: Observer>(&self, _ray: &Ray, _obs: &mut O) -> Option<Hit> {
        todo!()
    }
    /// Stub.
    pub fn any_hit<O: Observer>(&self, _ray: &Ray, _obs: &mut O) -> bool {
        todo!()
    }
    /// Stub.
    pub fn validate(&self) -> ValidationReport {
        todo!()
    }
}

/// Stub.
pub fn check_structure(
    _words: &[u32],
    _nodes: &std::ops::Range<usize>,
    _indices: &std::ops::Range<usize>,
    _triangles: usize,
) -> Result<(u64, u64), (usize, String)> {
    todo!()
}
