//! The quantized dual-split tree: the DST's planes as k-bit offsets inside a local frame,
//! several DST levels collapsed into one fetch (Lin et al. 2020, §5, future work).
//! INTEGRATION STUB: replaced by the real module on merge.

use crate::dst::{Dst, DstError};
use crate::image::MemoryImage;
use crate::observer::Observer;
use crate::validate::ValidationReport;
use dualsplit_geometry::{Aabb, Hit, Ray};

/// Stub.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct DstQConfig {
    /// Plane bits.
    pub bits: u32,
    /// Cluster bytes.
    pub cluster_bytes: u32,
}

impl DstQConfig {
    /// Stub.
    pub fn check(&self) -> Result<(), DstError> {
        todo!()
    }
}

impl Default for DstQConfig {
    fn default() -> Self {
        Self {
            bits: 8,
            cluster_bytes: 64,
        }
    }
}

/// Stub.
#[derive(Clone, Debug)]
pub struct DstQ {
    image: MemoryImage,
    cfg: DstQConfig,
}

impl DstQ {
    /// Stub.
    pub fn from_dst(_dst: &Dst, _cfg: &DstQConfig) -> Result<Self, DstError> {
        todo!()
    }
    /// Stub.
    pub fn from_image(
        _image: MemoryImage,
        _scene_box: Aabb,
        _cfg: DstQConfig,
    ) -> Result<Self, ValidationReport> {
        todo!()
    }
    /// Stub.
    pub fn from_parts(
        _image: MemoryImage,
        _scene_box: Aabb,
        _cfg: DstQConfig,
        _internal_nodes: usize,
        _leaves: usize,
    ) -> Self {
        todo!()
    }
    /// Stub.
    pub fn image(&self) -> &MemoryImage {
        &self.image
    }
    /// Stub.
    pub fn scene_box(&self) -> Aabb {
        todo!()
    }
    /// Stub.
    pub fn config(&self) -> &DstQConfig {
        &self.cfg
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
    pub fn validate(&self, _bvh: &crate::Bvh2) -> ValidationReport {
        todo!()
    }
}

/// Stub.
pub fn check_structure(
    _words: &[u32],
    _nodes: &std::ops::Range<usize>,
    _indices: &std::ops::Range<usize>,
    _triangles: usize,
    _cfg: &DstQConfig,
) -> Result<(u64, u64), (usize, String)> {
    todo!()
}
