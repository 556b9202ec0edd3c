//! stub
use super::Params;
use crate::{Camera, Light, SceneError};
use dualsplit_geometry::{Aabb, Triangle};
/// stub
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct ForestParams {}
impl ForestParams {
    /// stub
    pub fn from_params(_p: &mut Params) -> Result<Self, SceneError> {
        Ok(Self {})
    }
    /// stub
    pub fn triangles(&self) -> Vec<Triangle> {
        vec![]
    }
    /// stub
    pub fn camera(&self) -> Camera {
        Camera::fit(&Aabb::EMPTY)
    }
    /// stub
    pub fn light(&self) -> Light {
        Light::fit(&Aabb::EMPTY)
    }
}
