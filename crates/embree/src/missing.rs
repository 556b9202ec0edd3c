//! The scene when the crate was built without Embree: it cannot be made, so its queries
//! are unreachable.

use crate::{EmbreeError, EmbreeOptions};
use dualsplit_geometry::{Hit, Ray, Triangle};

/// A scene that does not exist.
pub(crate) struct Scene {
    never: std::convert::Infallible,
}

impl Scene {
    pub(crate) fn new(_: &[Triangle], _: &EmbreeOptions) -> Result<Self, EmbreeError> {
        Err(EmbreeError::Missing(crate::STATUS))
    }

    pub(crate) fn intersect(&self, _: &Ray) -> Option<Hit> {
        match self.never {}
    }

    pub(crate) fn occluded(&self, _: &Ray) -> bool {
        match self.never {}
    }

    pub(crate) fn version(&self) -> String {
        match self.never {}
    }

    pub(crate) fn triangles(&self) -> usize {
        match self.never {}
    }
}
