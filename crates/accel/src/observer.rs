//! The one-traversal contract (README, "What is where"): every traversal reports what it
//! does to an [`Observer`]. The CPU path passes [`NoObserver`], which compiles away;
//! statistics use [`CountingObserver`]; the simulator records macro-operations.

use dualsplit_geometry::PrimId;

/// A byte address in a memory image (word `i` is at byte `4 i`): what a traversal reports
/// to its [`Observer`] for every read, and where the simulator's loads go.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct ByteAddr(pub u64);

/// The kind of a dual-split tree node (the pipeline's derived 2-bit "node type").
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum DstNodeKind {
    /// Splitting node: two planes on one axis, two children.
    Split,
    /// Single-axis carving node: a slab on one axis, one child.
    SingleCarve,
    /// Dual-axis carving node: one plane on each of two axes, one child.
    DualCarve,
    /// Leaf word.
    Leaf,
}

/// Where a node step sends the ray, by how far it goes: nowhere (the stack is popped), into
/// one child, into both children (one entered, one pushed), or into the node's triangles.
/// A structure reports its own step results in these terms (the dual-split pipeline's
/// return codes 0–3 are these, in this order).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum StepOutcome {
    /// No child is entered.
    Miss = 0,
    /// One child is entered.
    OneChild = 1,
    /// Both children are entered: one now, the other pushed.
    BothChildren = 2,
    /// The node's triangles are tested.
    Leaf = 3,
}

impl StepOutcome {
    /// The four outcomes, in order.
    pub const ALL: [StepOutcome; 4] = [Self::Miss, Self::OneChild, Self::BothChildren, Self::Leaf];
}

/// One step of a traversal kernel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NodeStep {
    /// A BVH internal node: `arity` slots, `valid` non-empty children whose boxes were
    /// tested, `hits` of them intersected (and then sorted by entry distance).
    Bvh {
        /// Node width (2, 4, 8).
        arity: u8,
        /// Children actually present (empty slots hold degenerate boxes).
        valid: u8,
        /// Children whose box the ray intersects.
        hits: u8,
    },
    /// A dual-split tree node step: the node's kind and where the step sends the ray
    /// (Lin et al. 2020, §3).
    Dst {
        /// Node kind.
        kind: DstNodeKind,
        /// Where the step sends the ray: no child, one child, both children, the leaf.
        outcome: StepOutcome,
        /// For a carving node acting as a leaf (L bit set).
        carving_leaf: bool,
    },
    /// A leaf (BVH leaf or DST triangle run) about to be intersected.
    Leaf {
        /// Triangles in the run.
        count: u32,
    },
}

/// Told what a traversal kernel does, in order.
pub trait Observer {
    /// True for an observer that ignores every report ([`NoObserver`]): a BVH traversal may
    /// then answer from the CPU-side copy of the image ([`crate::wide::cpu`]), whose answers
    /// are the image traversal's bit for bit but whose reads are not the image's.
    const OBSERVES_NOTHING: bool = false;
    /// The kernel reads `bytes` contiguous bytes at byte address `addr` of the structure's
    /// memory image (node words, triangle-index entries, triangle vertices).
    #[inline(always)]
    fn fetch(&mut self, _addr: ByteAddr, _bytes: u32) {}
    /// The kernel reads one child box (`bytes` at `addr`) of the BVH node whose header it
    /// fetched last, to test it. A serial kernel reads each box as it tests it; a wide-box
    /// instruction reads the node's boxes at once, so an observer may join them.
    #[inline(always)]
    fn fetch_box(&mut self, addr: ByteAddr, bytes: u32) {
        self.fetch(addr, bytes);
    }
    /// A node step.
    #[inline(always)]
    fn step(&mut self, _step: NodeStep) {}
    /// A ray–triangle test of triangle `prim`; `hit` when it was accepted.
    #[inline(always)]
    fn triangle_test(&mut self, _prim: PrimId, _hit: bool) {}
    /// A traversal-stack push.
    #[inline(always)]
    fn push(&mut self) {}
    /// A traversal-stack pop (including entries discarded after the pop).
    #[inline(always)]
    fn pop(&mut self) {}
}

/// The observer that observes nothing.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoObserver;
impl Observer for NoObserver {
    const OBSERVES_NOTHING: bool = true;
}

/// Per-ray counters: nodes visited, planes/boxes tested, triangles tested, bytes fetched.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct CountingObserver {
    /// Internal node steps (BVH nodes, DST splitting and carving nodes).
    pub nodes: u64,
    /// Leaves entered.
    pub leaves: u64,
    /// Ray–box tests (BVH) — one per valid child box.
    pub box_tests: u64,
    /// Ray–plane tests (DST: two per internal node step).
    pub plane_tests: u64,
    /// Ray–triangle tests.
    pub triangle_tests: u64,
    /// Bytes fetched from the memory image.
    pub bytes: u64,
    /// Stack pushes.
    pub pushes: u64,
    /// DST steps by [`StepOutcome`], in its order.
    pub dst_codes: [u64; 4],
}

impl Observer for CountingObserver {
    #[inline]
    fn fetch(&mut self, _addr: ByteAddr, bytes: u32) {
        self.bytes += bytes as u64;
    }
    #[inline]
    fn step(&mut self, step: NodeStep) {
        match step {
            NodeStep::Bvh { valid, .. } => {
                self.nodes += 1;
                self.box_tests += valid as u64;
            }
            NodeStep::Dst { kind, outcome, .. } => {
                if kind != DstNodeKind::Leaf {
                    self.nodes += 1;
                    self.plane_tests += 2;
                }
                self.dst_codes[outcome as usize] += 1;
            }
            NodeStep::Leaf { .. } => self.leaves += 1,
        }
    }
    #[inline]
    fn triangle_test(&mut self, _prim: PrimId, _hit: bool) {
        self.triangle_tests += 1;
    }
    #[inline]
    fn push(&mut self) {
        self.pushes += 1;
    }
}

impl CountingObserver {
    /// Adds another counter set into this one.
    pub fn add(&mut self, o: &CountingObserver) {
        self.nodes += o.nodes;
        self.leaves += o.leaves;
        self.box_tests += o.box_tests;
        self.plane_tests += o.plane_tests;
        self.triangle_tests += o.triangle_tests;
        self.bytes += o.bytes;
        self.pushes += o.pushes;
        for i in 0..4 {
            self.dst_codes[i] += o.dst_codes[i];
        }
    }
}
