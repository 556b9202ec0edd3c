//! Every structure renders a bit-identical image (and identical ray counters) of the same
//! scene, for both workloads.

use dualsplit_accel::{AccelKind, BuildConfig, Structures};
use dualsplit_render::{RenderSettings, Workload, render};
use dualsplit_testkit::scenes::room;

#[test]
fn every_structure_renders_the_same_bits() {
    let scene = room(false, 12);
    let structures = Structures::build(&scene.triangles, &BuildConfig::default());
    for workload in Workload::ALL {
        let mut settings = RenderSettings::new(40, 30, workload);
        settings.spp = 2;
        let reference = render(&scene, &structures, AccelKind::Bvh2, &settings, &|| {}).unwrap();
        assert!(reference.counts.primary.hits > 0);
        assert!(reference.counts.shadow.rays > 0);
        for kind in AccelKind::ALL {
            let frame = render(&scene, &structures, kind, &settings, &|| {}).unwrap();
            assert_eq!(
                frame.counts,
                reference.counts,
                "{} {}",
                kind.name(),
                workload.name()
            );
            for (i, (a, b)) in frame
                .image
                .pixels
                .iter()
                .zip(&reference.image.pixels)
                .enumerate()
            {
                assert_eq!(
                    a.to_bits(),
                    b.to_bits(),
                    "{} {}: pixel ({}, {}) is {a}, BVH2 gives {b}",
                    kind.name(),
                    workload.name(),
                    i as u32 % settings.width,
                    i as u32 / settings.width
                );
            }
        }
    }
}
