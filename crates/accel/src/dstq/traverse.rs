//! The quantized DST's records for the one DST traversal (`dst/traverse.rs`, [`walk`]: the
//! exact DST's node rules, Lin et al. 2020, §3, Figs. 2–3), with each plane dequantized
//! from its cluster's frame (`plane = p_a + q · 2^(e_a − 127)`) before the same distance,
//! widening and `le_or_nan` tests. A record is named by its cluster's word address and its
//! bit position in the cluster; a stack entry carries both beside its interval.
//!
//! Fetch accounting (`docs/dstq-encoding.md`, §6): the frame (16 B at the cluster's start)
//! when the traversal starts working in a cluster other than the one whose frame it holds
//! (descending into a child cluster, or popping an entry of another cluster); then, per
//! node step, the whole 32-bit words that hold the record's bits (a record may straddle a
//! word boundary); 4 B per index entry and 36 B per triangle, as the exact DST.

use super::DstQ;
use super::frame::Frame;
use super::layout::{FRAME_WORDS, ROOT_BIT};
use super::record::{ChildRef, QHeader, RecordFormat, read_bits};
use crate::dst::HeaderOffset;
use crate::dst::traverse::{DstRecords, IndexRun, clip, walk};
use crate::image::MemoryImage;
use crate::observer::Observer;
use dualsplit_geometry::{Hit, Ray};

/// The quantized DST's records: the frame of the cluster last entered (fetched when the
/// traversal starts working in another cluster), and each record's bits.
struct QRecords<'a> {
    words: &'a [u32],
    /// Bits per plane offset.
    k: u32,
    fmt: RecordFormat,
    /// Words per cluster line.
    cw: usize,
    /// The word of the cluster whose frame is held (`u32::MAX`: none yet).
    frame_at: u32,
    frame: Frame,
}

/// A record of the quantized DST read: its header, where it is, and where its plane offsets
/// start.
#[derive(Clone, Copy)]
struct QRec<'a> {
    h: QHeader,
    cluster: u32,
    /// The cluster's words, to the end of its line.
    cwords: &'a [u32],
    /// Bit of the first plane offset in the cluster.
    planes_bit: u32,
}

impl QRecords<'_> {
    /// Where the child `c` of a record in the cluster at word `cluster` lies: (cluster word, bit).
    #[inline(always)]
    fn locate(cluster: u32, c: ChildRef) -> (u32, u32) {
        match c {
            ChildRef::Local(bit) => (cluster, bit),
            ChildRef::Cluster(b) => (b, ROOT_BIT),
        }
    }
}

impl<'a> DstRecords for QRecords<'a> {
    type At = (u32, u32);
    type Rec = QRec<'a>;

    #[inline(always)]
    fn read<O: Observer>(&mut self, (cluster, bit): (u32, u32), obs: &mut O) -> QRec<'a> {
        let base = cluster as usize;
        if cluster != self.frame_at {
            obs.fetch(MemoryImage::addr(base), 4 * FRAME_WORDS as u32);
            let mut fw = [0u32; 4];
            fw.copy_from_slice(&self.words[base..base + FRAME_WORDS]);
            self.frame = Frame::from_words(fw);
            self.frame_at = cluster;
        }
        // A cluster never crosses its line: its records lie before the line's end.
        let words: &'a [u32] = self.words;
        let cwords = &words[base..(base / self.cw + 1) * self.cw];
        let h = QHeader::read(read_bits(cwords, bit as usize, 32), &self.fmt);
        let (hb, rb) = (h.header_bits(&self.fmt), h.record_bits(&self.fmt));
        let (w0, w1) = (bit / 32, (bit + rb - 1) / 32);
        obs.fetch(MemoryImage::addr(base + w0 as usize), 4 * (w1 - w0 + 1));
        QRec {
            h,
            cluster,
            cwords,
            planes_bit: bit + hb,
        }
    }
    #[inline(always)]
    fn header(rec: QRec<'a>) -> HeaderOffset {
        rec.h.exact()
    }
    #[inline(always)]
    fn leaf_flag(rec: QRec<'a>) -> bool {
        rec.h.is_leaf_flag()
    }
    /// (The frame held is `rec`'s: a record's planes are read before the next record.)
    #[inline(always)]
    fn planes(&self, rec: QRec<'a>, a0: usize, a1: usize) -> (f32, f32) {
        let (cwords, k, bit) = (rec.cwords, self.k, rec.planes_bit as usize);
        (
            self.frame.plane(a0, read_bits(cwords, bit, k)),
            self.frame.plane(a1, read_bits(cwords, bit + k as usize, k)),
        )
    }
    #[inline(always)]
    fn split_children(&self, rec: QRec<'a>) -> ((u32, u32), (u32, u32)) {
        let (cb, lbit) = Self::locate(rec.cluster, rec.h.child(&self.fmt));
        ((cb, lbit), (cb, lbit + rec.h.left_bits(&self.fmt)))
    }
    #[inline(always)]
    fn child(&self, rec: QRec<'a>) -> (u32, u32) {
        Self::locate(rec.cluster, rec.h.child(&self.fmt))
    }
    #[inline(always)]
    fn run(rec: QRec<'a>) -> u32 {
        rec.h.run()
    }
}

impl DstQ {
    /// Closest hit of `ray`, ordered by `(t, prim)`: equal to the exact DST's and the BVH2's
    /// on every ray (conservative planes only add work). Lin et al. 2020, §3, §5.
    pub fn closest_hit<O: Observer>(&self, ray: &Ray, obs: &mut O) -> Option<Hit> {
        self.traverse::<O, false>(ray, obs)
    }

    /// True when `ray` hits any triangle within `[t_min, t_max]`.
    pub fn any_hit<O: Observer>(&self, ray: &Ray, obs: &mut O) -> bool {
        self.traverse::<O, true>(ray, obs).is_some()
    }

    fn traverse<O: Observer, const ANY: bool>(&self, ray: &Ray, obs: &mut O) -> Option<Hit> {
        if self.is_empty() {
            return None;
        }
        let (r, t_min, t_max) = clip(self.scene_box, ray)?;
        let img = &self.image;
        let words: &[u32] = &img.words;
        let runs = IndexRun {
            words,
            index_base: img.indices.start,
            tri_base: img.triangles.start,
            tris: self.triangles(),
        };
        let mut recs = QRecords {
            words,
            k: self.config.bits,
            fmt: self.config.record_format(),
            cw: self.config.cluster_words() as usize,
            frame_at: u32::MAX,
            frame: Frame {
                origin: [0.0; 3],
                exp: [0; 3],
            },
        };
        walk::<_, O, ANY>(&mut recs, &runs, &r, (0, ROOT_BIT), (t_min, t_max), obs)
    }
}
