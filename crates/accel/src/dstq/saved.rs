//! What the saved-tree format needs of a quantized DST (`crate::saved`): a tree from the
//! parts a file holds, and the check on load.

use super::{DstQ, DstQConfig};
use crate::image::MemoryImage;
use dualsplit_geometry::Aabb;

impl DstQ {
    /// The tree of `image` with the scene box and config a saved file's header records,
    /// unchecked: the loader runs [`DstQ::check_structure`] on it before handing it out.
    pub(crate) fn from_parts(image: MemoryImage, scene_box: Aabb, config: DstQConfig) -> Self {
        Self::assemble(image, scene_box, config)
    }

    /// The check on load of a saved quantized DST (`docs/tree-format.md`, "Checks on
    /// load"): [`DstQ::validate_structure`]'s walk; the first violation (the walk names the
    /// cluster and bit in its message).
    pub(crate) fn check_structure(&self) -> Result<(), (usize, String)> {
        let rep = self.validate_structure();
        match rep.errors.first() {
            Some(e) => Err((0, format!("{e} ({} violations)", rep.error_count))),
            None => Ok(()),
        }
    }
}
