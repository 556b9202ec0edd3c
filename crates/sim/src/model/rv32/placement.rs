//! Where the regions a thread addresses lie in the simulated DRAM, and so in the caches.
//!
//! The kernels address four regions far apart (`docs/isa.md`, "Memory map"): the memory
//! image from `0x0000_0000`, the parameter block at `0x7000_0000`, the frame buffer at
//! `0x7800_0000` and the program (whose `.rodata` the kernels load) at `0x8000_0000`. Those
//! bases are multiples of every cache size, so taken as they are they would make the
//! parameter block and the program's constants share a direct-mapped L1 and L2 index with
//! the image's first lines (the root node, read by every ray), and evict each other all
//! frame long. SimTRaX has no such aliasing: its main memory is one array holding the
//! parameters, the frame buffer and the scene one after another (`sim/LoadMemory.cc`: the
//! frame parameters at word 0, the frame buffer after the work queue at word 42, the scene
//! after the frame buffer).
//!
//! So the caches and DRAM see the regions packed one after another, each from a line
//! boundary: the parameter block, the program, the image, then the frame buffer (last, so
//! that where the scene lies does not depend on the frame size). Both thread models place
//! their loads with the same [`Placement`].

use crate::model::rv32::{FRAME_BUFFER_ADDR, PARAMS_ADDR, PROGRAM_BASE};

/// The physical (cache and DRAM) byte address of each region's first byte.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Placement {
    params: u64,
    program: u64,
    image: u64,
    frame: u64,
}

impl Placement {
    /// Regions of `params_bytes`, `program_bytes`, `image_bytes` placed in that order from
    /// address 0, each from a multiple of `line_bytes`; the frame buffer follows the image.
    pub fn new(params_bytes: u64, program_bytes: u64, image_bytes: u64, line_bytes: u64) -> Self {
        let up = |x: u64| x.div_ceil(line_bytes.max(1)) * line_bytes.max(1);
        let program = up(params_bytes);
        let image = program + up(program_bytes);
        let frame = image + up(image_bytes);
        Self {
            params: 0,
            program,
            image,
            frame,
        }
    }

    /// The physical address of the image's byte 0.
    #[inline]
    pub fn image_base(&self) -> u64 {
        self.image
    }

    /// The physical address of thread byte address `addr` (below the local store).
    #[inline]
    pub fn physical(&self, addr: u32) -> u64 {
        let a = addr as u64;
        if addr < PARAMS_ADDR {
            self.image + a
        } else if addr < FRAME_BUFFER_ADDR {
            self.params + (a - PARAMS_ADDR as u64)
        } else if addr < PROGRAM_BASE {
            self.frame + (a - FRAME_BUFFER_ADDR as u64)
        } else {
            self.program + (a - PROGRAM_BASE as u64)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn regions_are_packed_from_line_boundaries_in_order() {
        let p = Placement::new(100, 9000, 5000, 64);
        assert_eq!(p.physical(PARAMS_ADDR), 0);
        assert_eq!(p.physical(PARAMS_ADDR + 99), 99);
        assert_eq!(p.physical(PROGRAM_BASE), 128);
        assert_eq!(p.physical(0), 128 + 9024);
        assert_eq!(p.image_base(), 128 + 9024);
        assert_eq!(p.physical(4999), 128 + 9024 + 4999);
        assert_eq!(p.physical(FRAME_BUFFER_ADDR), 128 + 9024 + 5056);
    }

    #[test]
    fn no_two_regions_share_a_line() {
        let p = Placement::new(4, 4, 4, 64);
        let lines: Vec<u64> = [PARAMS_ADDR, PROGRAM_BASE, 0, FRAME_BUFFER_ADDR]
            .iter()
            .map(|&a| p.physical(a) / 64)
            .collect();
        assert_eq!(lines, [0, 1, 2, 3]);
    }
}
