//! Scene files made from public meshes: the paper's Dragon Box (Lin et al. 2020, Table 3)
//! as SimTRaX ships it, a reconstruction of it made before that scene was found, the
//! compact PLY writer of the shipped scene files, and the triangles' SHA-256 that
//! `scripts/get-scenes.sh` checks converted files by.
//!
//! **The Dragon Box** ([`dragon_box`]) is SimTRaX's sample scene `samples/scenes/dragon/`
//! (github.com/dkoptacs/simtrax, commit `f2537ff`, "Adding dragon sample scene"):
//! `dragon.objl` lists `dragon.obj` (the Stanford dragon in its original coordinates) and
//! then `dragon_box.obj`, a closed axis-aligned box of 12 triangles ([`SIMTRAX_BOX`],
//! [`simtrax_box`]). So the scene is the dragon's triangles, unchanged and first, then the
//! box's 12 in the file's vertex and face order: 871,414 + 12 = 871,426 triangles for the
//! full dragon, the paper's "870K". Its camera and light are `dragon.view` and
//! `dragon.light` (`Camera::preset_for`, `Light::preset_for`).
//!
//! **The reconstruction** ([`reconstructed_dragon_box`]) is the dragon followed by 10
//! triangles: an axis-aligned cube open on +z whose side is 1.5 × the dragon's largest
//! extent, centred on the dragon in x and z, with its floor at the dragon's lowest y. The
//! corners are computed in f64 from the f32 bounds and rounded to f32 once. Every box
//! triangle faces into the box. [`closed_reconstructed_dragon_box`] closes it behind its
//! camera.
//!
//! ```
//! use dualsplit_geometry::{Triangle, Vec3};
//! let dragon = vec![Triangle::new(Vec3::ZERO, Vec3::X, Vec3::new(0.0, 2.0, 0.0))];
//! let scene = dualsplit_scene::make::reconstructed_dragon_box(&dragon);
//! assert_eq!(scene.len(), 11);
//! assert_eq!(&scene[..1], &dragon[..]);
//! let simtrax = dualsplit_scene::make::dragon_box(&dragon);
//! assert_eq!(simtrax.len(), 13);
//! ```
use dualsplit_geometry::{Aabb, Triangle, Vec3};
use std::collections::HashMap;
use std::io::Write;
use std::path::Path;

/// SimTRaX's Dragon Box walls, from the comments of `samples/scenes/dragon/dragon_box.obj`
/// (commit `f2537ff`, lines 2-7): left, right, bottom, top, front, back.
pub const SIMTRAX_BOX: [f32; 6] = [-0.128813, 0.117055, 0.0382846, 0.2116174, 0.11, -0.119];

/// Triangles of SimTRaX's closed box.
pub const SIMTRAX_BOX_TRIANGLES: usize = 12;

/// The 12 triangles of `dragon_box.obj` (SimTRaX commit `f2537ff`), in its order: vertices
/// 1-4 the top corners (left front, left back, right back, right front), 5-8 the bottom
/// ones in the same order (lines 10-19), faces top, back, bottom, front, left, right as
/// written (lines 24-45; `f a b c` uses vertices a, b, c, counted from 1).
pub fn simtrax_box() -> [Triangle; SIMTRAX_BOX_TRIANGLES] {
    let [l, r, b, t, f, k] = SIMTRAX_BOX;
    let v = [
        Vec3::new(l, t, f),
        Vec3::new(l, t, k),
        Vec3::new(r, t, k),
        Vec3::new(r, t, f),
        Vec3::new(l, b, f),
        Vec3::new(l, b, k),
        Vec3::new(r, b, k),
        Vec3::new(r, b, f),
    ];
    let faces: [[usize; 3]; SIMTRAX_BOX_TRIANGLES] = [
        [1, 2, 3], // top
        [3, 4, 1],
        [2, 3, 7], // back
        [7, 6, 2],
        [5, 6, 7], // bottom
        [7, 8, 5],
        [1, 4, 8], // front
        [8, 5, 1],
        [1, 2, 6], // left
        [6, 5, 1],
        [3, 4, 8], // right
        [8, 7, 3],
    ];
    faces.map(|[a, b, c]| Triangle::new(v[a - 1], v[b - 1], v[c - 1]))
}

/// The bounds of [`simtrax_box`].
pub fn simtrax_box_bounds() -> Aabb {
    let [l, r, b, t, f, k] = SIMTRAX_BOX;
    Aabb::new(Vec3::new(l, b, k), Vec3::new(r, t, f))
}

/// The paper's Dragon Box as SimTRaX ships it: `dragon`'s triangles, then [`simtrax_box`]
/// (see the module documentation). The box stands at fixed coordinates: the dragon must be
/// the Stanford dragon in its original coordinates (or one of its decimations) to lie
/// inside it, which [`check_dragon_box`] checks.
pub fn dragon_box(dragon: &[Triangle]) -> Vec<Triangle> {
    let mut out = Vec::with_capacity(dragon.len() + SIMTRAX_BOX_TRIANGLES);
    out.extend_from_slice(dragon);
    out.extend(simtrax_box());
    out
}

/// Triangles the reconstruction's box adds: five faces of two triangles (floor, top, back,
/// left, right).
pub const BOX_TRIANGLES: usize = 10;

/// The box's side over the dragon's largest extent.
pub const SIDE_OVER_EXTENT: f64 = 1.5;

/// The 10 triangles of the reconstruction's open box around `bounds` (see the module
/// documentation).
pub fn open_box(bounds: &Aabb) -> [Triangle; BOX_TRIANGLES] {
    let (lo, hi) = (bounds.min.as_dvec3(), bounds.max.as_dvec3());
    let centre = (lo + hi) / 2.0;
    let side = SIDE_OVER_EXTENT * (hi - lo).max_element();
    let half = side / 2.0;
    let (x0, x1) = ((centre.x - half) as f32, (centre.x + half) as f32);
    let (z0, z1) = ((centre.z - half) as f32, (centre.z + half) as f32);
    let (y0, y1) = (lo.y as f32, (lo.y + side) as f32);
    // Bottom corners counter-clockwise seen from above, then the top ones.
    let c = [
        Vec3::new(x0, y0, z0),
        Vec3::new(x1, y0, z0),
        Vec3::new(x1, y0, z1),
        Vec3::new(x0, y0, z1),
        Vec3::new(x0, y1, z0),
        Vec3::new(x1, y1, z0),
        Vec3::new(x1, y1, z1),
        Vec3::new(x0, y1, z1),
    ];
    let faces: [[usize; 3]; BOX_TRIANGLES] = [
        [0, 3, 2], // floor
        [0, 2, 1],
        [4, 5, 6], // top
        [4, 6, 7],
        [0, 1, 5], // back (-z)
        [0, 5, 4],
        [0, 4, 7], // left (-x)
        [0, 7, 3],
        [1, 2, 6], // right (+x)
        [1, 6, 5],
    ];
    faces.map(|[a, b, d]| Triangle::new(c[a], c[b], c[d]))
}

/// Triangles [`closed_reconstructed_dragon_box`] adds to the open box: the floor, top and side walls
/// carried on past the open side, and a front wall behind the camera.
pub const CLOSING_TRIANGLES: usize = 10;

/// How far behind the preset camera the front wall of the closed box stands, as a fraction
/// of the box's side.
pub const CLOSING_WALL_BEHIND_EYE: f64 = 0.1;

/// The reconstruction closed behind its camera: [`reconstructed_dragon_box`], then
/// [`CLOSING_TRIANGLES`] that carry the floor, top and side walls on along +z from the open
/// side to a front wall standing [`CLOSING_WALL_BEHIND_EYE`] × the side behind the preset
/// camera of `dragon_box_recon`. Saved as `dragon_box_recon_closed` (or the older name
/// `dragon_box_closed`), it is seen and lit as the open box is (its camera and light
/// presets are the open box's), so rays that leave through the open side stay in the scene.
pub fn closed_reconstructed_dragon_box(dragon: &[Triangle]) -> Vec<Triangle> {
    let mut out = reconstructed_dragon_box(dragon);
    let open = out[dragon.len()..]
        .iter()
        .fold(Aabb::EMPTY, |b, t| b.union(t.bounds()));
    let eye = crate::Camera::preset_for("dragon_box_recon", &open).eye;
    let (lo, hi) = (open.min, open.max);
    let side = f64::from(hi.y - lo.y);
    let zw = (f64::from(eye.z) + CLOSING_WALL_BEHIND_EYE * side) as f32;
    let (x0, x1, y0, y1, z1) = (lo.x, hi.x, lo.y, hi.y, hi.z);
    let p = Vec3::new;
    let quad =
        |a: Vec3, b: Vec3, c: Vec3, d: Vec3| [Triangle::new(a, b, c), Triangle::new(a, c, d)];
    out.extend(
        [
            quad(p(x0, y0, z1), p(x0, y0, zw), p(x1, y0, zw), p(x1, y0, z1)), // floor
            quad(p(x0, y1, z1), p(x1, y1, z1), p(x1, y1, zw), p(x0, y1, zw)), // top
            quad(p(x0, y0, z1), p(x0, y1, z1), p(x0, y1, zw), p(x0, y0, zw)), // left
            quad(p(x1, y0, z1), p(x1, y0, zw), p(x1, y1, zw), p(x1, y1, z1)), // right
            quad(p(x0, y0, zw), p(x0, y1, zw), p(x1, y1, zw), p(x1, y0, zw)), // front
        ]
        .into_iter()
        .flatten(),
    );
    out
}

/// The reconstructed Dragon Box of `dragon`: its triangles, then [`open_box`] of their
/// bounds.
pub fn reconstructed_dragon_box(dragon: &[Triangle]) -> Vec<Triangle> {
    let bounds = dragon.iter().fold(Aabb::EMPTY, |b, t| b.union(t.bounds()));
    let mut out = Vec::with_capacity(dragon.len() + BOX_TRIANGLES);
    out.extend_from_slice(dragon);
    out.extend(open_box(&bounds));
    out
}

/// Checks a Dragon Box made by [`dragon_box`], [`reconstructed_dragon_box`] or
/// [`closed_reconstructed_dragon_box`] from the `dragon_len` triangles of `spec` before it
/// is written
/// ([`SceneError::Make`](crate::SceneError::Make) otherwise): every triangle the box adds has an area (a dragon of a single point, or one
/// too thin for f32, gives a box of zero size), and the whole scene is one every loader
/// accepts ([`Scene::from_triangles`](crate::Scene::from_triangles): the box is 1.5 × the
/// dragon's extent, so a dragon near [`Scene::MAX_EXTENT`](crate::Scene::MAX_EXTENT) makes
/// a box beyond it).
pub fn check_dragon_box(
    spec: &str,
    dragon_len: usize,
    triangles: &[Triangle],
) -> Result<(), crate::SceneError> {
    let bad = |reason: String| crate::SceneError::Make {
        spec: spec.to_string(),
        what: "the Dragon Box",
        reason,
    };
    if let Some(i) = triangles[dragon_len.min(triangles.len())..]
        .iter()
        .position(Triangle::is_degenerate)
    {
        let dragon = triangles[..dragon_len.min(triangles.len())]
            .iter()
            .fold(Aabb::EMPTY, |b, t| b.union(t.bounds()));
        return Err(bad(format!(
            "box triangle {i} has no area (the input's bounds {:?} to {:?} have no extent for f32)",
            dragon.min, dragon.max
        )));
    }
    crate::Scene::from_triangles(spec, spec, triangles.to_vec(), Default::default())
        .map(drop)
        .map_err(|e| bad(format!("the result would not load: {e}")))
}

/// Checks that `dragon` (the triangles of `spec`) lies inside [`simtrax_box`], as the
/// Stanford dragon in its original coordinates does; [`SceneError::Make`](crate::SceneError::Make)
/// otherwise (a mesh in other coordinates would stand outside SimTRaX's fixed box).
pub fn check_inside_simtrax_box(spec: &str, dragon: &[Triangle]) -> Result<(), crate::SceneError> {
    let b = dragon.iter().fold(Aabb::EMPTY, |b, t| b.union(t.bounds()));
    let walls = simtrax_box_bounds();
    if dragon.is_empty() || !walls.contains_box(&b) {
        return Err(crate::SceneError::Make {
            spec: spec.to_string(),
            what: "SimTRaX's Dragon Box",
            reason: format!(
                "the input's bounds {:?} to {:?} are not inside SimTRaX's box {:?} to {:?}: \
                 give the Stanford dragon in its original coordinates, or use \
                 --reconstruction for a box fitted to any mesh",
                b.min, b.max, walls.min, walls.max
            ),
        });
    }
    Ok(())
}

/// The PLY bytes of `triangles` in the shipped files' shape (binary little-endian, float
/// x y z vertices, `uchar uint` index lists), each `comments` line as a `comment`. Vertices
/// with the same bits are written once, in order of first use, so a loaded file gives back
/// `triangles` bit for bit.
pub fn ply_bytes(triangles: &[Triangle], comments: &[&str]) -> Vec<u8> {
    let mut index: HashMap<[u32; 3], u32> = HashMap::new();
    let mut verts: Vec<[u32; 3]> = Vec::new();
    let mut faces: Vec<[u32; 3]> = Vec::with_capacity(triangles.len());
    for t in triangles {
        faces.push(t.v.map(|p| {
            let key = p.to_array().map(f32::to_bits);
            *index.entry(key).or_insert_with(|| {
                verts.push(key);
                (verts.len() - 1) as u32
            })
        }));
    }
    let mut out = String::from("ply\nformat binary_little_endian 1.0\n");
    for c in comments {
        out.push_str(&format!("comment {}\n", c.replace('\n', " ")));
    }
    out.push_str(&format!(
        "element vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
         element face {}\nproperty list uchar uint vertex_indices\nend_header\n",
        verts.len(),
        faces.len()
    ));
    let mut bytes = out.into_bytes();
    bytes.reserve(verts.len() * 12 + faces.len() * 13);
    for v in &verts {
        for b in v {
            bytes.extend_from_slice(&b.to_le_bytes());
        }
    }
    for f in &faces {
        bytes.push(3);
        for i in f {
            bytes.extend_from_slice(&i.to_le_bytes());
        }
    }
    bytes
}

/// The SHA-256 (lowercase hex) of `triangles` as 36-byte records of nine little-endian
/// f32s (v0 xyz, v1 xyz, v2 xyz) in order: the same for any file that loads to the same
/// triangles, whatever its format, vertex sharing or compression.
pub fn triangles_sha256(triangles: &[Triangle]) -> String {
    use sha2::{Digest, Sha256};
    let mut h = Sha256::new();
    for t in triangles {
        for p in &t.v {
            for c in p.to_array() {
                h.update(c.to_le_bytes());
            }
        }
    }
    h.finalize().iter().map(|b| format!("{b:02x}")).collect()
}

/// Writes [`ply_bytes`] gzipped to `path` (the gzip header's time is zero, so the bytes
/// depend only on the triangles and comments).
pub fn write_ply_gz(path: &Path, triangles: &[Triangle], comments: &[&str]) -> std::io::Result<()> {
    let file = std::fs::File::create(path)?;
    let mut gz = flate2::GzBuilder::new().mtime(0).write(
        std::io::BufWriter::new(file),
        flate2::Compression::default(),
    );
    gz.write_all(&ply_bytes(triangles, comments))?;
    gz.finish()?.flush()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lopsided() -> Vec<Triangle> {
        vec![
            Triangle::new(
                Vec3::new(-1.0, 0.5, 0.0),
                Vec3::new(3.0, 0.5, 0.25),
                Vec3::new(0.0, 2.0, -0.5),
            ),
            Triangle::new(
                Vec3::new(3.0, 0.5, 0.25),
                Vec3::new(-1.0, 0.5, 0.0),
                Vec3::new(1.0, 1.0, 1.0),
            ),
        ]
    }

    #[test]
    fn the_box_is_a_cube_on_the_floor_open_on_plus_z_facing_inwards() {
        let dragon = lopsided();
        let all = reconstructed_dragon_box(&dragon);
        assert_eq!(all.len(), dragon.len() + BOX_TRIANGLES);
        assert_eq!(&all[..2], &dragon[..]);
        let b = all[2..]
            .iter()
            .fold(Aabb::EMPTY, |b, t| b.union(t.bounds()));
        // Largest extent 4 (x): side 6, centred at x = 1 and z = 0.25, floor at y = 0.5.
        assert_eq!(b.min, Vec3::new(-2.0, 0.5, -2.75));
        assert_eq!(b.max, Vec3::new(4.0, 6.5, 3.25));
        let centre = (b.min + b.max) / 2.0;
        for t in &all[2..] {
            let n = (t.v[1] - t.v[0]).cross(t.v[2] - t.v[0]);
            assert!(n.length() > 0.0);
            assert!(n.dot(centre - t.v[0]) > 0.0, "{t:?} faces outwards");
            // No triangle lies in the +z plane: the box is open there.
            assert!(t.v.iter().any(|v| v.z < b.max.z), "{t:?} closes +z");
        }
    }

    #[test]
    fn simtrax_box_is_closed_and_has_the_file_s_walls() {
        let tris = simtrax_box();
        let b = tris.iter().fold(Aabb::EMPTY, |b, t| b.union(t.bounds()));
        assert_eq!(b, simtrax_box_bounds());
        assert_eq!(b.min, Vec3::new(-0.128813, 0.0382846, -0.119));
        assert_eq!(b.max, Vec3::new(0.117055, 0.2116174, 0.11));
        // Two triangles in each of the six wall planes: the box is closed.
        let on = |axis: usize, v: f32| {
            tris.iter()
                .filter(|t| t.v.iter().all(|p| p.to_array()[axis] == v))
                .count()
        };
        for axis in 0..3 {
            assert_eq!(on(axis, b.min.to_array()[axis]), 2, "axis {axis} min");
            assert_eq!(on(axis, b.max.to_array()[axis]), 2, "axis {axis} max");
        }
        // Face 1 of the file is `f 1 2 3`: top left front, top left back, top right back.
        assert_eq!(tris[0].v[0], Vec3::new(-0.128813, 0.2116174, 0.11));
        assert_eq!(tris[0].v[2], Vec3::new(0.117055, 0.2116174, -0.119));
        let scene = dragon_box(&lopsided());
        assert_eq!(scene.len(), 2 + SIMTRAX_BOX_TRIANGLES);
        assert_eq!(&scene[2..], &tris[..]);
    }

    #[test]
    fn a_mesh_outside_simtrax_s_box_is_refused() {
        let err = check_inside_simtrax_box("lopsided", &lopsided()).unwrap_err();
        assert!(
            err.to_string().contains("not inside SimTRaX's box"),
            "{err}"
        );
        assert!(check_inside_simtrax_box("none", &[]).is_err());
        let inside = [Triangle::new(
            Vec3::new(0.0, 0.1, 0.0),
            Vec3::new(0.01, 0.1, 0.0),
            Vec3::new(0.0, 0.11, 0.0),
        )];
        assert!(check_inside_simtrax_box("inside", &inside).is_ok());
    }

    #[test]
    fn the_triangle_hash_covers_every_coordinate_in_order() {
        let a = lopsided();
        let mut b = a.clone();
        b.swap(0, 1);
        let mut c = a.clone();
        c[1].v[2].z = f32::from_bits(c[1].v[2].z.to_bits() + 1);
        let h = triangles_sha256(&a);
        assert_eq!(h.len(), 64);
        assert_ne!(h, triangles_sha256(&b));
        assert_ne!(h, triangles_sha256(&c));
        // The empty input's hash is SHA-256 of no bytes.
        assert_eq!(
            triangles_sha256(&[]),
            "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855"
        );
    }

    #[test]
    fn ply_bytes_weld_identical_vertices_and_keep_the_header_shape() {
        let tris = reconstructed_dragon_box(&lopsided());
        let bytes = ply_bytes(&tris, &["made by a test"]);
        let text = String::from_utf8_lossy(&bytes[..200]);
        assert!(text.starts_with("ply\nformat binary_little_endian 1.0\ncomment made by a test\n"));
        // 4 distinct dragon vertices and 8 corners.
        assert!(text.contains("element vertex 12\n"), "{text}");
        assert!(text.contains("element face 12\n"), "{text}");
        let header = text.find("end_header\n").unwrap() + "end_header\n".len();
        assert_eq!(bytes.len(), header + 12 * 12 + 12 * 13);
    }
}

#[cfg(test)]
mod closed_box_tests {
    use super::*;
    use crate::{Camera, Light};

    #[test]
    fn the_closed_box_is_seen_and_lit_as_the_open_one_from_inside() {
        let dragon = vec![
            Triangle::new(Vec3::ZERO, Vec3::X, Vec3::new(0.0, 2.0, 0.5)),
            Triangle::new(Vec3::new(0.3, 0.1, -0.4), Vec3::X, Vec3::new(0.7, 1.0, 0.2)),
        ];
        let open = reconstructed_dragon_box(&dragon);
        let closed = closed_reconstructed_dragon_box(&dragon);
        assert_eq!(closed.len(), open.len() + CLOSING_TRIANGLES);
        assert_eq!(&closed[..open.len()], &open[..]);
        let bounds = |t: &[Triangle]| t.iter().fold(Aabb::EMPTY, |b, t| b.union(t.bounds()));
        let (ob, cb) = (bounds(&open), bounds(&closed));
        let (oc, cc) = (
            Camera::preset_for("dragon_box_recon", &ob),
            Camera::preset_for("dragon_box_recon_closed", &cb),
        );
        assert_eq!(
            (oc.eye, oc.target, oc.fov_y_deg),
            (cc.eye, cc.target, cc.fov_y_deg)
        );
        let (ol, cl) = (
            Light::preset_for("dragon_box_recon", &ob),
            Light::preset_for("dragon_box_recon_closed", &cb),
        );
        assert_eq!((ol.position, ol.radius), (cl.position, cl.radius));
        // The eye is inside the closed box, in front of the open side, behind the front wall.
        let inside = (cc.eye.cmpgt(cb.min) & cc.eye.cmplt(cb.max)).all();
        assert!(inside, "{:?} outside {cb:?}", cc.eye);
        assert!(cc.eye.z > ob.max.z && cc.eye.z < cb.max.z);
    }
}
