//! How the Embree scene is built.

/// Build options of an [`EmbreeScene`](crate::EmbreeScene). The default is what a new user
/// gets from Embree: medium build quality (binned SAH), no robust mode, one build thread per
/// core.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct EmbreeOptions {
    /// `RTC_SCENE_FLAG_ROBUST`: Embree avoids optimisations that lose accuracy (its
    /// watertight mode); slower.
    pub robust: bool,
    /// `RTC_BUILD_QUALITY_HIGH` (spatial splits) instead of the default medium quality.
    pub high_quality: bool,
    /// `max_isa=avx2` of the device configuration: Embree's kernels limited to AVX2. On a
    /// CPU with AVX-512 Embree otherwise runs its AVX-512 kernels (`avx512::` intersectors
    /// over the same BVH8), where our traversals use AVX2 at most.
    pub avx2_at_most: bool,
    /// Threads Embree's builder may use (`threads=N` of the device configuration); `None`:
    /// every core. Tracing runs on the caller's threads whatever this says.
    pub build_threads: Option<usize>,
}
