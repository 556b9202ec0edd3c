//! What can go wrong when Embree is asked for a scene.

/// An error of the Embree wrapper.
#[derive(Debug, thiserror::Error)]
pub enum EmbreeError {
    /// The library was not found (or was turned off) when this crate was built.
    #[error("the Embree peer is missing: {0}")]
    Missing(&'static str),
    /// An Embree call reported an error (`rtcGetDeviceError`).
    #[error("Embree {call} failed: {code}")]
    Call {
        /// The API call (or the step) that failed.
        call: &'static str,
        /// Embree's error code.
        code: ErrorCode,
    },
    /// The loaded library is not one the bindings were written for.
    #[error("the Embree library at run time is unsupported: {0}")]
    Unsupported(String),
    /// Embree's index buffer holds 32-bit vertex indices, three per triangle.
    #[error("{triangles} triangles need more vertices than Embree's 32-bit indices address")]
    TooLarge {
        /// Triangles in the scene.
        triangles: usize,
    },
}

/// Embree's `enum RTCError`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ErrorCode {
    /// `RTC_ERROR_NONE` where a call still returned nothing.
    None,
    /// `RTC_ERROR_UNKNOWN`.
    Unknown,
    /// `RTC_ERROR_INVALID_ARGUMENT`.
    InvalidArgument,
    /// `RTC_ERROR_INVALID_OPERATION`.
    InvalidOperation,
    /// `RTC_ERROR_OUT_OF_MEMORY`.
    OutOfMemory,
    /// `RTC_ERROR_UNSUPPORTED_CPU`.
    UnsupportedCpu,
    /// `RTC_ERROR_CANCELLED`.
    Cancelled,
    /// A code this crate does not know.
    Other(u32),
}

impl ErrorCode {
    /// The code of Embree's numeric `RTCError`.
    pub fn from_raw(code: u32) -> Self {
        match code {
            0 => Self::None,
            1 => Self::Unknown,
            2 => Self::InvalidArgument,
            3 => Self::InvalidOperation,
            4 => Self::OutOfMemory,
            5 => Self::UnsupportedCpu,
            6 => Self::Cancelled,
            c => Self::Other(c),
        }
    }
}

impl std::fmt::Display for ErrorCode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::None => f.write_str("no error code (a null handle)"),
            Self::Unknown => f.write_str("unknown error"),
            Self::InvalidArgument => f.write_str("invalid argument"),
            Self::InvalidOperation => f.write_str("invalid operation"),
            Self::OutOfMemory => f.write_str("out of memory"),
            Self::UnsupportedCpu => f.write_str("unsupported CPU"),
            Self::Cancelled => f.write_str("cancelled"),
            Self::Other(c) => write!(f, "error code {c}"),
        }
    }
}
