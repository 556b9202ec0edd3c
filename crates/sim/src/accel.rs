//! The simulated configurations: which structure, traversed how, on which units.
//!
//! Every configuration is registered once, in the `sim_accels!` invocation below: its
//! variant, command-line name, the paper's label, the traversal it runs, the TM unit that
//! tests its nodes ([`NodeUnit`]), its ray-box pipes for the "+" configurations, its chart
//! colour, and its compiled kernels, one per workload
//! and variant (`kernels/build/<name>-{cast,path}{,-parity,-loads,-parity-loads,-parity-loads-sortall}.elf`, which `kernels/Makefile`'s
//! `CONFIGS` builds; a test checks the two lists agree). The CLI, the simulator, the kernel table, the
//! calibration and the charts read it from here (`docs/extending.md`).

use crate::config::{KernelsConfig, SimConfig, UnitConfig};
use crate::hw::pipe::TmPipes;
use dualsplit_accel::AccelKind;
use serde::{Deserialize, Serialize};

/// One kernel ELF of `kernels/build/`, compiled into the binary.
macro_rules! kernel {
    ($name:expr) => {
        include_bytes!(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../kernels/build/",
            $name
        ))
    };
}

/// Defines [`SimAccel`] and its registry from one list.
macro_rules! sim_accels {
    ($(
        $(#[doc = $doc:literal])*
        $v:ident = $name:literal, $label:literal, $kind:ident, unit: $unit:ident,
            parallel: $par:expr, color: $rgb:expr;
    )*) => {
        /// The simulated configurations: the paper's eight (§4) and the quantized structures'
        /// three (beyond the paper).
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
        #[serde(rename_all = "kebab-case")]
        pub enum SimAccel {
            $( $(#[doc = $doc])* $v, )*
        }

        impl SimAccel {
            /// All, in the paper's table order.
            pub const ALL: [SimAccel; [$($name),*].len()] = [$(SimAccel::$v),*];

            /// The registry entry of `self`.
            const fn info(self) -> &'static Info {
                &INFO[self as usize]
            }
        }

        const INFO: [Info; [$($name),*].len()] = [$(
            Info {
                name: $name,
                label: $label,
                kind: AccelKind::$kind,
                unit: NodeUnit::$unit,
                parallel: $par,
                color: $rgb,
                kernels: [
                    [
                        kernel!(concat!($name, "-cast.elf")),
                        kernel!(concat!($name, "-cast-parity.elf")),
                        kernel!(concat!($name, "-cast-loads.elf")),
                        kernel!(concat!($name, "-cast-parity-loads.elf")),
                        kernel!(concat!($name, "-cast-parity-loads-sortall.elf")),
                    ],
                    [
                        kernel!(concat!($name, "-path.elf")),
                        kernel!(concat!($name, "-path-parity.elf")),
                        kernel!(concat!($name, "-path-loads.elf")),
                        kernel!(concat!($name, "-path-parity-loads.elf")),
                        kernel!(concat!($name, "-path-parity-loads-sortall.elf")),
                    ],
                ],
            },
        )*];
    };
}

/// What the registry knows of one configuration.
struct Info {
    name: &'static str,
    label: &'static str,
    kind: AccelKind,
    /// The unit that tests its nodes.
    unit: NodeUnit,
    /// Ray-box pipes testing all of a node's children in one issue slot (the "+"
    /// configurations), if any.
    parallel: Option<u32>,
    color: [u8; 3],
    /// The compiled kernels, cast then path, each in the order of [`KernelsConfig::ALL`].
    kernels: [[&'static [u8]; KernelsConfig::ALL.len()]; 2],
}

/// The TM unit that tests a configuration's nodes: what its kernels issue a node to, and
/// what the `fast` model charges a node step as.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum NodeUnit {
    /// The ray-box pipelines, one child box per op.
    BoxPipe,
    /// The quantized ray-box pipelines: one issue per node, every one of its 8 slots
    /// dequantized and tested (`rt.qboxn`).
    QuantizedBoxPipe,
    /// None: the kernel decodes dual-split nodes with its own instructions (DST\*).
    SoftwareDualSplit,
    /// The dual-split pipeline (`rt.dstp`).
    DualSplitPipe,
    /// The quantized dual-split pipeline (`rt.dstqp`).
    QuantizedDualSplitPipe,
}

impl NodeUnit {
    /// A dual-split tree's nodes (stack entries carry `[t_min, t_max]`), on a pipeline or
    /// in software.
    pub fn is_dual_split(self) -> bool {
        matches!(
            self,
            NodeUnit::SoftwareDualSplit
                | NodeUnit::DualSplitPipe
                | NodeUnit::QuantizedDualSplitPipe
        )
    }

    /// A dual-split pipeline, exact or quantized.
    pub fn is_dual_split_pipe(self) -> bool {
        matches!(
            self,
            NodeUnit::DualSplitPipe | NodeUnit::QuantizedDualSplitPipe
        )
    }
}

sim_accels! {
    /// BVH2, child boxes tested one after another on the TM's ray-box pipeline.
    Bvh2 = "bvh2", "BVH2", Bvh2, unit: BoxPipe,
        parallel: None, color: [31, 90, 180];
    /// BVH2 with 2 ray-box pipelines (all child boxes in parallel).
    Bvh2Plus = "bvh2+", "BVH2+", Bvh2, unit: BoxPipe,
        parallel: Some(2), color: [110, 160, 230];
    /// BVH4, serial box tests.
    Bvh4 = "bvh4", "BVH4", Bvh4, unit: BoxPipe,
        parallel: None, color: [30, 130, 60];
    /// BVH4 with 4 ray-box pipelines.
    Bvh4Plus = "bvh4+", "BVH4+", Bvh4, unit: BoxPipe,
        parallel: Some(4), color: [120, 200, 120];
    /// BVH8, serial box tests.
    Bvh8 = "bvh8", "BVH8", Bvh8, unit: BoxPipe,
        parallel: None, color: [200, 110, 0];
    /// BVH8 with 8 ray-box pipelines.
    Bvh8Plus = "bvh8+", "BVH8+", Bvh8, unit: BoxPipe,
        parallel: Some(8), color: [245, 180, 80];
    /// DST decoded in software (DST*).
    DstSw = "dst-sw", "DST*", DstSw, unit: SoftwareDualSplit,
        parallel: None, color: [130, 70, 170];
    /// DST on the dual-split pipeline.
    Dst = "dst", "DST", Dst, unit: DualSplitPipe,
        parallel: None, color: [210, 30, 40];
    /// Compressed BVH8 (beyond the paper): one quantized ray-box pipeline, the 8 child
    /// tests of a node one after another.
    Cwbvh = "cwbvh", "CWBVH", Cwbvh, unit: QuantizedBoxPipe,
        parallel: None, color: [90, 90, 90];
    /// Compressed BVH8 with 8 quantized ray-box pipelines (all children in one issue).
    CwbvhPlus = "cwbvh+", "CWBVH+", Cwbvh, unit: QuantizedBoxPipe,
        parallel: Some(8), color: [170, 170, 170];
    /// Quantized DST on the quantized dual-split pipeline (beyond the paper).
    DstQ = "dst-q", "DST-Q", DstQ, unit: QuantizedDualSplitPipe,
        parallel: None, color: [240, 110, 160];
}

impl SimAccel {
    /// The configuration simulated when none is named: the DST on the paper's dual-split
    /// pipeline.
    pub const DEFAULT: SimAccel = SimAccel::Dst;

    /// The paper's eight configurations (§4, Tables 4–7), in its table order.
    pub const PAPER: [SimAccel; 8] = [
        SimAccel::Bvh2,
        SimAccel::Bvh2Plus,
        SimAccel::Bvh4,
        SimAccel::Bvh4Plus,
        SimAccel::Bvh8,
        SimAccel::Bvh8Plus,
        SimAccel::DstSw,
        SimAccel::Dst,
    ];

    /// The configurations of the report's "Beyond the paper" study: the baseline, the
    /// paper's wide BVH and DST, and the quantized structures.
    pub const BEYOND: [SimAccel; 7] = [
        SimAccel::Bvh2,
        SimAccel::Bvh8,
        SimAccel::Bvh8Plus,
        SimAccel::Dst,
        SimAccel::Cwbvh,
        SimAccel::CwbvhPlus,
        SimAccel::DstQ,
    ];

    /// Command-line name: `bvh2`, `bvh2+`, ..., `dst-sw`, `dst`, `cwbvh`, `cwbvh+`, `dst-q`.
    pub fn name(self) -> &'static str {
        self.info().name
    }
    /// The paper's label: `BVH2`, `BVH2+`, ..., `DST*`, `DST`; `CWBVH`, `CWBVH+`, `DST-Q`.
    pub fn label(self) -> &'static str {
        self.info().label
    }
    /// Parses a command-line name.
    pub fn parse(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|k| k.name() == s)
    }
    /// The command-line names, comma-separated, for help and messages.
    pub fn names() -> String {
        Self::ALL.map(SimAccel::name).join(", ")
    }
    /// The traversal this configuration runs.
    pub fn kind(self) -> AccelKind {
        self.info().kind
    }
    /// The "+" configurations: all child boxes of a node tested in one issue slot, on as
    /// many ray-box pipelines (§4).
    pub fn parallel_boxes(self) -> bool {
        self.info().parallel.is_some()
    }
    /// The unit that tests its nodes.
    pub fn node_unit(self) -> NodeUnit {
        self.info().unit
    }
    /// The traversal of a dual-split tree (stack entries carry `[t_min, t_max]`):
    /// [`NodeUnit::is_dual_split`].
    pub fn is_dst(self) -> bool {
        self.node_unit().is_dual_split()
    }
    /// One of the paper's eight configurations ([`SimAccel::PAPER`]).
    pub fn in_paper(self) -> bool {
        Self::PAPER.contains(&self)
    }
    /// Ray-box pipelines per TM: the node arity for the "+" configurations (§4), else the
    /// configuration's `units.box_pipes`.
    pub fn box_pipes(self, cfg: &SimConfig) -> u32 {
        self.info().parallel.unwrap_or(cfg.units.box_pipes)
    }
    /// The pipelines of each TM in this configuration: [`SimAccel::box_pipes`] ray-box pipes,
    /// quantized when its [`NodeUnit`] is, and a quantized dual-split pipeline when its unit
    /// is that.
    pub fn pipes(self, units: &UnitConfig) -> TmPipes {
        TmPipes {
            box_pipes: self.info().parallel.unwrap_or(units.box_pipes),
            quantized_boxes: self.node_unit() == NodeUnit::QuantizedBoxPipe,
            quantized_dst: self.node_unit() == NodeUnit::QuantizedDualSplitPipe,
        }
    }
    /// The colour of its series in the report's charts (RGB).
    pub fn color(self) -> [u8; 3] {
        self.info().color
    }
    /// Its compiled kernel for workload `cast` (`path == false`) or `path` in `variant`: an
    /// RV32IMF ELF.
    pub fn kernel(self, path: bool, variant: KernelsConfig) -> &'static [u8] {
        self.info().kernels[path as usize][variant.index()]
    }
}
