//! Cameras and lights: a fit to the bounds for unknown scenes, presets for the shipped scene
//! files (keyed by file stem), and command-line overrides.
//!
//! The paper renders each test scene from one fixed view (Lin et al. 2020, §4, Fig. 6); the
//! presets play that role for the shipped mesh files (`docs/scenes.md`), each showing its
//! subject (the dragon inside its box, the Sponza courtyard from inside, the dragons in a
//! row). Presets are expressed relative to the scene bounds, so a rescaled file still gets a
//! sensible view.

use dualsplit_geometry::{Aabb, Vec3};
use serde::{Deserialize, Serialize};

/// A pinhole camera.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Camera {
    /// Eye position.
    pub eye: Vec3,
    /// Point looked at.
    pub target: Vec3,
    /// Up vector.
    pub up: Vec3,
    /// Vertical field of view in degrees.
    pub fov_y_deg: f32,
}

/// A spherical area light (radius 0 = point light).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Light {
    /// Centre.
    pub position: Vec3,
    /// Radius; shadow rays aim at a point sampled on the sphere.
    pub radius: f32,
    /// Radiant intensity (linear RGB, grey here).
    pub intensity: f32,
}

/// Farthest a camera's eye or target, or a light's centre, may lie from the origin on any
/// axis: 2^62 ≈ 4.6e18. A scene lies within ±[`Scene::MAX_COORDINATE`](crate::Scene::MAX_COORDINATE)
/// = 2^60, and the fitted camera of the widest scene stands within ±3.3 · 2^60; within
/// these bounds (and a light radius of at most 2^60) a view direction's and a shadow ray's
/// squared length stay below f32's largest value (3 · (1.5 · 2^62)² ≈ 1.2e38), so no shadow
/// ray is lost to an overflowing distance.
pub const MAX_VIEW_COORDINATE: f32 = (1u64 << 62) as f32;

/// A bad camera or light override from the command line.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CameraError {
    /// A vector is not three comma-separated finite numbers.
    #[error("--{what} `{value}`: expected three finite numbers `x,y,z`")]
    BadVector {
        /// Which option (`eye`, `target`, `light`).
        what: &'static str,
        /// The text given.
        value: String,
    },
    /// A scalar is out of its range (or not finite).
    #[error("--{what} {value}: must be {range}")]
    OutOfRange {
        /// Which option (`fov`, `light-radius`, `light-intensity`).
        what: &'static str,
        /// The value given.
        value: f32,
        /// The range, in words.
        range: &'static str,
    },
    /// A position lies farther than [`MAX_VIEW_COORDINATE`] (2^62) from the origin on some
    /// axis: the light's distance to the scene and the view direction would overflow f32.
    #[error(
        "--{what} `{value}`: a coordinate lies beyond ±{limit:e} (2^62, the limit of camera and light positions)"
    )]
    Far {
        /// Which option (`eye`, `target`, `light`).
        what: &'static str,
        /// The text given.
        value: String,
        /// [`MAX_VIEW_COORDINATE`].
        limit: f32,
    },
    /// The eye and the target coincide, or the view direction is parallel to up.
    #[error(
        "camera eye {eye:?} and target {target:?} give no view direction (equal, or looking straight along up)"
    )]
    NoViewDirection {
        /// Eye.
        eye: Vec3,
        /// Target.
        target: Vec3,
    },
}

/// Parses `x,y,z` (spaces allowed) into a finite vector.
pub fn parse_vec3(what: &'static str, s: &str) -> Result<Vec3, CameraError> {
    let bad = || CameraError::BadVector {
        what,
        value: s.to_string(),
    };
    let v: Vec<f32> = s
        .split(',')
        .map(|c| c.trim().parse::<f32>())
        .collect::<Result<_, _>>()
        .map_err(|_| bad())?;
    match v[..] {
        [x, y, z] if x.is_finite() && y.is_finite() && z.is_finite() => Ok(Vec3::new(x, y, z)),
        _ => Err(bad()),
    }
}

fn check_range(
    what: &'static str,
    value: f32,
    ok: bool,
    range: &'static str,
) -> Result<f32, CameraError> {
    if ok {
        Ok(value)
    } else {
        Err(CameraError::OutOfRange { what, value, range })
    }
}

/// [`parse_vec3`], refusing a point beyond ±[`MAX_VIEW_COORDINATE`].
fn parse_point(what: &'static str, s: &str) -> Result<Vec3, CameraError> {
    let v = parse_vec3(what, s)?;
    let limit = MAX_VIEW_COORDINATE;
    if v.abs().max_element() > limit {
        return Err(CameraError::Far {
            what,
            value: s.to_string(),
            limit,
        });
    }
    Ok(v)
}

/// Which preset a stem gets in bounds `b`. The closed reconstruction
/// (`dragon_box_recon_closed`, or its older name `dragon_box_closed`;
/// [`crate::make::closed_reconstructed_dragon_box`]) is seen and lit exactly as the open
/// one: its presets are the open box's, placed in the open box's bounds, which are the
/// closed box's cut back to a cube (the open box is a cube; the closed one only extends it
/// along +z). A `dragon_box` is SimTRaX's scene when its bounds are SimTRaX's box
/// ([`crate::make::simtrax_box_bounds`]: the box encloses the dragon, so they are exactly
/// the box's), and otherwise a reconstruction made before SimTRaX's scene was used (such a
/// file may still be named `dragon_box.ply.gz`).
fn open_box_view<'a>(stem: &'a str, b: &Aabb) -> (&'a str, Aabb) {
    match stem {
        "dragon_box_closed" | "dragon_box_recon_closed" => {
            let mut open = *b;
            open.max.z = open.min.z + b.extent().y;
            ("dragon_box_recon", open)
        }
        "dragon_box" if *b != crate::make::simtrax_box_bounds() => ("dragon_box_recon", *b),
        "dragon_box" => (SIMTRAX_DRAGON_BOX, *b),
        _ => (stem, *b),
    }
}

/// The internal preset name of SimTRaX's Dragon Box (a `dragon_box` in SimTRaX's box).
const SIMTRAX_DRAGON_BOX: &str = "dragon_box (SimTRaX)";

/// SimTRaX's `samples/scenes/dragon/dragon.view` (commit `f2537ff`), read as
/// `sim/ReadViewfile.cc:21-26` reads it: eye, view direction, up, aperture, image plane
/// left, right, bottom, top, and its distance.
pub const SIMTRAX_DRAGON_VIEW: [f32; 15] = [
    -0.008, 0.11, 0.108903, 0.0, 0.0, -1.0, 0.0, 1.0, 0.0, 0.0, -1.0, 1.0, -1.0, 1.0, 1.015,
];

/// SimTRaX's `samples/scenes/dragon/dragon.light` (commit `f2537ff`): a point light,
/// read by `sim/ReadLightfile.cc:13-14` as a position.
pub const SIMTRAX_DRAGON_LIGHT: [f32; 3] = [0.0, 0.2, 0.0];

/// The camera of [`SIMTRAX_DRAGON_VIEW`]: the eye, looking along the view direction, up as
/// given, the vertical field of view of the image plane's top and bottom at its distance,
/// 2·atan(1/1.015) = 89.15° (a pinhole: the aperture is 0).
fn simtrax_dragon_camera() -> Camera {
    let v = SIMTRAX_DRAGON_VIEW;
    let eye = Vec3::new(v[0], v[1], v[2]);
    let dir = Vec3::new(v[3], v[4], v[5]);
    let (bottom, top, dist) = (f64::from(v[12]), f64::from(v[13]), f64::from(v[14]));
    let half = (top.atan2(dist) - bottom.atan2(dist)) / 2.0;
    Camera {
        eye,
        target: eye + dir,
        up: Vec3::new(v[6], v[7], v[8]),
        fov_y_deg: (2.0 * half).to_degrees() as f32,
    }
}

/// A view relative to the bounds: looks at `target` (fractions of the box, 0 = min, 1 = max)
/// from `eye` (same fractions), or, when `eye` is `None`, from direction `dir` at the distance
/// that fits the box's bounding sphere scaled by `zoom`.
struct View {
    target: [f32; 3],
    eye: Option<[f32; 3]>,
    dir: Vec3,
    zoom: f32,
    fov: f32,
}

impl View {
    fn camera(&self, b: &Aabb) -> Camera {
        // Fraction 0.5 is exactly the centre (`(min + max) / 2`, not `min + extent / 2`).
        let at = |f: [f32; 3]| {
            let f = Vec3::from_array(f);
            Vec3::select(
                f.cmpeq(Vec3::splat(0.5)),
                b.center(),
                b.min + b.extent() * f,
            )
        };
        let target = at(self.target);
        let eye = match self.eye {
            Some(e) => at(e),
            None => {
                let r = (b.extent().length() * 0.5).max(1e-3);
                let dist = r / (self.fov.to_radians() * 0.5).sin() * self.zoom;
                target + self.dir.normalize() * dist
            }
        };
        Camera {
            eye,
            target,
            up: Vec3::Y,
            fov_y_deg: self.fov,
        }
    }
}

/// The shipped files' views, by stem (y is up in all of them, see `docs/scenes.md`).
fn preset_view(stem: &str) -> Option<View> {
    Some(match stem {
        // The dragon alone: three-quarter view of its left side, slightly from above.
        "dragon" | "dragon_res2" | "dragon_res3" | "dragon_res4" => View {
            target: [0.5, 0.45, 0.5],
            eye: None,
            dir: Vec3::new(0.45, 0.3, 1.0),
            zoom: 0.72,
            fov: 40.0,
        },
        "bunny" => View {
            target: [0.5, 0.45, 0.5],
            eye: None,
            dir: Vec3::new(0.2, 0.25, 1.0),
            zoom: 0.72,
            fov: 40.0,
        },
        // The reconstruction: the dragon inside its box, seen through the open +z side.
        "dragon_box_recon" => View {
            target: [0.5, 0.28, 0.45],
            eye: None,
            dir: Vec3::new(0.12, 0.15, 1.0),
            zoom: 0.7,
            fov: 45.0,
        },
        // Inside the courtyard from its west end, looking down the arcades.
        "sponza_dabrovic" => View {
            target: [0.9, 0.38, 0.47],
            eye: Some([0.1, 0.2, 0.56]),
            dir: Vec3::X,
            zoom: 1.0,
            fov: 60.0,
        },
        // The paper's Crytek Sponza (the glTF sample, scaled to metres): from inside the
        // atrium at its east end, a quarter of its height up, looking west down the nave,
        // slightly up toward the arcades (the paper shows only a thumbnail of this view).
        "crytek_sponza" => View {
            target: [0.08, 0.3, 0.5],
            eye: Some([0.9, 0.22, 0.5]),
            dir: Vec3::X,
            zoom: 1.0,
            fov: 60.0,
        },
        // The row of dragons on the courtyard floor, seen diagonally from a corner.
        "dragon_sponza" => View {
            target: [0.5, 0.11, 0.487],
            eye: Some([0.155, 0.248, 0.577]),
            dir: Vec3::X,
            zoom: 1.0,
            fov: 55.0,
        },
        _ => return None,
    })
}

impl Camera {
    /// A camera looking at the centre of `b` from the front (+z), a little from the right and
    /// above, at the distance where the box's bounding sphere just fills a 45° view. Used for
    /// files without a preset (y assumed up, as in most mesh files).
    pub fn fit(b: &Aabb) -> Self {
        View {
            target: [0.5, 0.5, 0.5],
            eye: None,
            dir: Vec3::new(0.35, 0.35, 1.0),
            zoom: 1.0,
            fov: 45.0,
        }
        .camera(b)
    }

    /// The preset view of a shipped scene file by its stem (`dragon_box`, `sponza_dabrovic`,
    /// …; see `docs/scenes.md`), placed relative to `bounds`; [`Camera::fit`] for any other
    /// stem.
    pub fn preset_for(stem: &str, bounds: &Aabb) -> Self {
        let (stem, bounds) = open_box_view(stem, bounds);
        if stem == SIMTRAX_DRAGON_BOX {
            return simtrax_dragon_camera();
        }
        preset_view(stem).map_or_else(|| Self::fit(&bounds), |v| v.camera(&bounds))
    }

    /// True when `stem` has a preset view.
    pub fn has_preset(stem: &str) -> bool {
        preset_view(stem).is_some()
            || matches!(
                stem,
                "dragon_box" | "dragon_box_closed" | "dragon_box_recon_closed"
            )
    }

    /// This camera with command-line overrides: `eye` and `target` as `x,y,z`, `fov` the
    /// vertical field of view in degrees (0, 180).
    pub fn with_overrides(
        &self,
        eye: Option<&str>,
        target: Option<&str>,
        fov: Option<f32>,
    ) -> Result<Self, CameraError> {
        let mut c = *self;
        if let Some(e) = eye {
            c.eye = parse_point("eye", e)?;
        }
        if let Some(t) = target {
            c.target = parse_point("target", t)?;
        }
        if let Some(f) = fov {
            c.fov_y_deg = check_range(
                "fov",
                f,
                f > 0.0 && f < 180.0,
                "strictly between 0 and 180 degrees",
            )?;
        }
        let fwd = c.target - c.eye;
        if fwd.length_squared() == 0.0 || fwd.cross(c.up).length_squared() == 0.0 {
            return Err(CameraError::NoViewDirection {
                eye: c.eye,
                target: c.target,
            });
        }
        Ok(c)
    }
}

impl Light {
    /// A light above the scene, in front of it and to the left of a fitted camera, so
    /// shadows fall visibly to the right and back. Its radius is 2 % of the scene radius.
    pub fn fit(b: &Aabb) -> Self {
        let c = b.center();
        let e = b.extent();
        let r = (e.length() * 0.5).max(1e-3);
        Self {
            position: c + Vec3::new(-0.5 * r, 1.1 * r, 0.8 * r),
            radius: r * 0.02,
            intensity: 1.0,
        }
    }

    /// The preset light of a shipped scene file by its stem, relative to `bounds`;
    /// [`Light::fit`] for any other stem.
    pub fn preset_for(stem: &str, b: &Aabb) -> Self {
        let (stem, b) = open_box_view(stem, b);
        let b = &b;
        let at = |f: [f32; 3]| b.min + b.extent() * Vec3::from_array(f);
        let r = (b.extent().length() * 0.5).max(1e-3);
        match stem {
            // SimTRaX's point light over the dragon.
            SIMTRAX_DRAGON_BOX => Self {
                position: Vec3::from_array(SIMTRAX_DRAGON_LIGHT),
                radius: 0.0,
                intensity: 1.0,
            },
            // The reconstruction: under the top of the box, toward the open side; the
            // dragon casts a shadow on the floor and the back wall.
            "dragon_box_recon" => Self {
                position: at([0.3, 0.85, 0.75]),
                radius: r * 0.02,
                intensity: 1.0,
            },
            // High over the open courtyard: sun-like light falling into the atrium.
            "sponza_dabrovic" | "dragon_sponza" | "crytek_sponza" => Self {
                position: at([0.4, 0.95, 0.5]),
                radius: r * 0.01,
                intensity: 1.0,
            },
            _ => Self::fit(b),
        }
    }

    /// This light with command-line overrides: `position` as `x,y,z`, `radius` ≥ 0 (0 is
    /// a point light) and `intensity` > 0.
    pub fn with_overrides(
        &self,
        position: Option<&str>,
        radius: Option<f32>,
        intensity: Option<f32>,
    ) -> Result<Self, CameraError> {
        let mut l = *self;
        if let Some(p) = position {
            l.position = parse_point("light", p)?;
        }
        if let Some(r) = radius {
            // Radius 0 is a point light; -0 is taken as 0.
            let ok = (0.0..=crate::Scene::MAX_COORDINATE).contains(&r);
            l.radius =
                check_range("light-radius", r, ok, "from 0 to 2^60 (1.1529215e18)")?.max(0.0);
        }
        if let Some(i) = intensity {
            let ok = i > 0.0 && i.is_finite();
            l.intensity = check_range("light-intensity", i, ok, "a finite number above 0")?;
        }
        Ok(l)
    }
}
