//! Files of rays (`dualsplit trace --rays FILE`): raw little-endian records of 32 bytes,
//! one per ray, `f32` origin x, y, z, direction x, y, z, `t_min`, `t_max` (the layout of
//! [`Ray`]).
//!
//! A file holds at most [`MAX_RAYS`] rays, and every ray must be
//! [traceable](Ray::is_traceable): a finite origin and direction, no NaN interval end
//! (`t_max = +∞` is the usual unbounded ray). A ray outside that rule is refused with its
//! index and field rather than answered, so no caller mistakes the traversals' defined miss
//! for an answer.

use dualsplit_geometry::{Ray, Vec3};

/// Bytes of one ray record.
pub const RAY_BYTES: usize = 32;

/// Most rays of one file: 2^25 (1 GiB of records; `trace` holds them, their answers and
/// the file at once, about 2.5 GiB).
pub const MAX_RAYS: u64 = 1 << 25;

/// Largest ray file read: [`MAX_RAYS`] records.
pub const MAX_BYTES: u64 = MAX_RAYS * RAY_BYTES as u64;

/// A ray file that cannot be used.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum RayFileError {
    /// The length is not a multiple of [`RAY_BYTES`].
    #[error("{len} bytes is not a whole number of {RAY_BYTES}-byte ray records")]
    Partial {
        /// Bytes in the file.
        len: u64,
    },
    /// More than [`MAX_RAYS`] records.
    #[error("{count} rays; at most {MAX_RAYS} in one file")]
    TooMany {
        /// Records in the file.
        count: u64,
    },
    /// A ray that is not [traceable](Ray::is_traceable).
    #[error(
        "ray {index}: {field} is {value}; rays need a finite origin and direction and no NaN t_min or t_max"
    )]
    Untraceable {
        /// The ray's index (0-based, in file order).
        index: u64,
        /// The first bad field (`origin.x`, ..., `t_max`).
        field: &'static str,
        /// Its value.
        value: f32,
    },
}

/// Checks that ray `index` is traceable ([`RayFileError::Untraceable`] otherwise).
pub fn check_ray(index: u64, ray: &Ray) -> Result<(), RayFileError> {
    match ray.untraceable_field() {
        None => Ok(()),
        Some((field, value)) => Err(RayFileError::Untraceable {
            index,
            field,
            value,
        }),
    }
}

/// The rays of a ray file's `bytes`, checked (see the module).
pub fn parse_rays(bytes: &[u8]) -> Result<Vec<Ray>, RayFileError> {
    let len = bytes.len() as u64;
    if !bytes.len().is_multiple_of(RAY_BYTES) {
        return Err(RayFileError::Partial { len });
    }
    let count = len / RAY_BYTES as u64;
    if count > MAX_RAYS {
        return Err(RayFileError::TooMany { count });
    }
    bytes
        .chunks_exact(RAY_BYTES)
        .enumerate()
        .map(|(i, r)| {
            let f =
                |i: usize| f32::from_le_bytes([r[4 * i], r[4 * i + 1], r[4 * i + 2], r[4 * i + 3]]);
            let ray = Ray {
                origin: Vec3::new(f(0), f(1), f(2)),
                dir: Vec3::new(f(3), f(4), f(5)),
                t_min: f(6),
                t_max: f(7),
            };
            check_ray(i as u64, &ray).map(|()| ray)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn file(vals: &[f32]) -> Vec<u8> {
        vals.iter().flat_map(|v| v.to_le_bytes()).collect()
    }

    #[test]
    fn ray_records_are_read_in_order_and_partial_records_refused() {
        let vals: Vec<f32> = (0..16).map(|i| i as f32).collect();
        let bytes = file(&vals);
        let rays = parse_rays(&bytes).unwrap();
        assert_eq!(rays.len(), 2);
        assert_eq!(rays[1].origin, Vec3::new(8.0, 9.0, 10.0));
        assert_eq!((rays[1].t_min, rays[1].t_max), (14.0, 15.0));
        assert_eq!(
            parse_rays(&bytes[..40]),
            Err(RayFileError::Partial { len: 40 })
        );
    }

    #[test]
    fn untraceable_rays_are_refused_by_index_and_field() {
        let mut vals: Vec<f32> = vec![0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, f32::INFINITY];
        vals.extend_from_slice(&[0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, f32::NAN]);
        let e = parse_rays(&file(&vals)).unwrap_err();
        assert!(
            matches!(e, RayFileError::Untraceable { index: 1, field: "t_max", value } if value.is_nan()),
            "{e:?}"
        );
        assert!(e.to_string().starts_with("ray 1: t_max is NaN"), "{e}");
        vals[9] = f32::NEG_INFINITY;
        let e = parse_rays(&file(&vals)).unwrap_err();
        assert!(e.to_string().starts_with("ray 1: origin.y is -inf"), "{e}");
    }
}
