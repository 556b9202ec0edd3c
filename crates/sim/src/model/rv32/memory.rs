//! Global memory as the threads see it (`docs/isa.md`, "Memory map"), and the global
//! register file.
//!
//! The [`Memory`] trait covers what all threads share: the structure's memory image, the
//! parameter block, the frame buffer and the global registers. The program region and the
//! TP's private local store are not behind the trait: the [`super::Hart`] reads the
//! [`super::Program`] and its own local store directly.
//!
//! [`FrameMemory`] is the concrete map for one frame:
//!
//! | range | backing | access |
//! |---|---|---|
//! | `0x0000_0000 ..` | [`MemoryImage::words`] (nodes, indices), then [`MemoryImage::triangle_data`] at `4 · triangles.start` | read-only |
//! | `0x7000_0000 ..` | the parameter block (bytes given by the caller) | read-only |
//! | `0x7800_0000 ..` | the frame buffer (sized by the caller, zeroed) | read-write |
//!
//! Anything else is unmapped. Accesses are little-endian; alignment is checked by the hart
//! before the trait is called.

use dualsplit_accel::MemoryImage;

/// Byte address of the parameter block.
pub const PARAMS_ADDR: u32 = 0x7000_0000;
/// Byte address of the frame buffer.
pub const FRAME_BUFFER_ADDR: u32 = 0x7800_0000;
/// Byte address of the local store.
pub const LOCAL_STORE_ADDR: u32 = 0xF000_0000;
/// Number of global registers in [`FrameMemory`].
pub const GLOBAL_REGISTERS: usize = 8;

#[cfg(target_endian = "big")]
compile_error!("FrameMemory views the image's u32 words as little-endian bytes");

/// Why a global access failed (the hart adds the pc).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MemFault {
    /// No region maps the address (or the access runs past a region's end).
    Unmapped,
    /// A store to a read-only region.
    ReadOnly,
    /// `rt.atominc` on a global register that does not exist.
    NoGlobal,
    /// A read-only view ([`ImageView`]) was asked for what only the whole memory has (the
    /// frame buffer, a store, the global registers): the engine's local phase leaves such
    /// an access to its commit phase.
    Elsewhere,
}

/// Global memory and the global register file, shared by all threads.
///
/// Addresses are byte addresses below [`super::PROGRAM_BASE`]; word and half-word accesses
/// arrive aligned.
pub trait Memory {
    /// Reads the `N` bytes at `addr`.
    fn load<const N: usize>(&mut self, addr: u32) -> Result<[u8; N], MemFault>;
    /// Writes `bytes` at `addr`.
    fn store<const N: usize>(&mut self, addr: u32, bytes: [u8; N]) -> Result<(), MemFault>;
    /// Reads `out.len()` consecutive words from `addr` (the operands of `rt.box`, `rt.boxn`,
    /// `rt.tri`, `rt.dst`).
    #[inline]
    fn load_words(&mut self, addr: u32, out: &mut [u32]) -> Result<(), MemFault> {
        for (k, w) in out.iter_mut().enumerate() {
            *w = u32::from_le_bytes(self.load::<4>(addr.wrapping_add(4 * k as u32))?);
        }
        Ok(())
    }
    /// `rt.atominc`: `G[index] += 1`, returning the old value.
    fn atominc(&mut self, index: u32) -> Result<u32, MemFault>;
}

/// The read-only part of a frame's memory, the structure's image and the parameter block:
/// what a thread may read in the event loop's local phase, while other host threads run
/// theirs. Anything else is [`MemFault::Elsewhere`].
#[derive(Clone, Copy, Debug)]
pub struct ImageView<'a> {
    words: &'a [u8],
    tri_base: u32,
    tris: &'a [u8],
    params: &'a [u8],
}

impl ImageView<'_> {
    /// The region and offset of `addr` below the frame buffer.
    #[inline(always)]
    fn slice(&self, addr: u32) -> Option<(&[u8], usize)> {
        if addr < PARAMS_ADDR {
            let a = addr as usize;
            if a < self.words.len() {
                Some((self.words, a))
            } else {
                Some((self.tris, addr.checked_sub(self.tri_base)? as usize))
            }
        } else {
            Some((self.params, (addr - PARAMS_ADDR) as usize))
        }
    }
}

impl Memory for ImageView<'_> {
    #[inline(always)]
    fn load<const N: usize>(&mut self, addr: u32) -> Result<[u8; N], MemFault> {
        if addr >= FRAME_BUFFER_ADDR {
            return Err(MemFault::Elsewhere);
        }
        let (s, o) = self.slice(addr).ok_or(MemFault::Unmapped)?;
        get(s, o).ok_or(MemFault::Unmapped)
    }

    fn store<const N: usize>(&mut self, _: u32, _: [u8; N]) -> Result<(), MemFault> {
        Err(MemFault::Elsewhere)
    }

    #[inline]
    fn load_words(&mut self, addr: u32, out: &mut [u32]) -> Result<(), MemFault> {
        if addr >= FRAME_BUFFER_ADDR {
            return Err(MemFault::Elsewhere);
        }
        let (s, o) = self.slice(addr).ok_or(MemFault::Unmapped)?;
        words(s, o, out)
    }

    fn atominc(&mut self, _: u32) -> Result<u32, MemFault> {
        Err(MemFault::Elsewhere)
    }
}

/// Reads `out.len()` little-endian words from `s` at offset `o`.
#[inline(always)]
fn words(s: &[u8], o: usize, out: &mut [u32]) -> Result<(), MemFault> {
    let b = s.get(o..o + 4 * out.len()).ok_or(MemFault::Unmapped)?;
    for (w, c) in out.iter_mut().zip(b.chunks_exact(4)) {
        *w = u32::from_le_bytes([c[0], c[1], c[2], c[3]]);
    }
    Ok(())
}

/// The memory of one frame: a structure's image, a parameter block, a frame buffer and
/// [`GLOBAL_REGISTERS`] global registers (all zero at the start).
#[derive(Debug)]
pub struct FrameMemory<'a> {
    image: ImageView<'a>,
    /// The frame buffer's bytes (3 little-endian f32 per pixel for the kernels of
    /// `kernels/`).
    pub frame: Vec<u8>,
    /// The global registers `G`.
    pub globals: [u32; GLOBAL_REGISTERS],
}

impl<'a> FrameMemory<'a> {
    /// Maps `image` at 0, `params` at [`PARAMS_ADDR`] and a zeroed frame buffer of
    /// `frame_bytes` bytes at [`FRAME_BUFFER_ADDR`].
    ///
    /// # Panics
    /// If the image or parameter block overlap the next region (an image of 1.75 GiB).
    pub fn new(image: &'a MemoryImage, params: &'a [u8], frame_bytes: usize) -> Self {
        let words: &[u8] = bytemuck::cast_slice(&image.words[..]);
        let tris: &[u8] = bytemuck::cast_slice(image.triangle_slice());
        let tri_base = (image.triangles.start as u64 * 4) as u32;
        assert!(
            (tri_base as u64 + tris.len() as u64) <= PARAMS_ADDR as u64,
            "image too large"
        );
        assert!(params.len() <= (FRAME_BUFFER_ADDR - PARAMS_ADDR) as usize);
        assert!(frame_bytes <= (super::PROGRAM_BASE - FRAME_BUFFER_ADDR) as usize);
        FrameMemory {
            image: ImageView {
                words,
                tri_base,
                tris,
                params,
            },
            frame: vec![0; frame_bytes],
            globals: [0; GLOBAL_REGISTERS],
        }
    }

    /// The frame buffer as f32 values (little-endian words).
    pub fn frame_f32(&self) -> Vec<f32> {
        self.frame
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect()
    }

    /// The read-only part: the image and the parameter block.
    pub fn view(&self) -> ImageView<'a> {
        self.image
    }

    #[inline(always)]
    fn slice(&self, addr: u32) -> Option<(&[u8], usize)> {
        if addr < FRAME_BUFFER_ADDR {
            self.image.slice(addr)
        } else {
            Some((&self.frame, (addr - FRAME_BUFFER_ADDR) as usize))
        }
    }
}

#[inline(always)]
fn get<const N: usize>(s: &[u8], o: usize) -> Option<[u8; N]> {
    s.get(o..o + N)?.try_into().ok()
}

impl Memory for FrameMemory<'_> {
    #[inline(always)]
    fn load<const N: usize>(&mut self, addr: u32) -> Result<[u8; N], MemFault> {
        if addr >= super::PROGRAM_BASE {
            return Err(MemFault::Unmapped);
        }
        let (s, o) = self.slice(addr).ok_or(MemFault::Unmapped)?;
        get(s, o).ok_or(MemFault::Unmapped)
    }

    #[inline(always)]
    fn store<const N: usize>(&mut self, addr: u32, bytes: [u8; N]) -> Result<(), MemFault> {
        if !(FRAME_BUFFER_ADDR..super::PROGRAM_BASE).contains(&addr) {
            return if addr < FRAME_BUFFER_ADDR && self.slice(addr).is_some() {
                Err(MemFault::ReadOnly)
            } else {
                Err(MemFault::Unmapped)
            };
        }
        let o = (addr - FRAME_BUFFER_ADDR) as usize;
        self.frame
            .get_mut(o..o + N)
            .ok_or(MemFault::Unmapped)?
            .copy_from_slice(&bytes);
        Ok(())
    }

    #[inline]
    fn load_words(&mut self, addr: u32, out: &mut [u32]) -> Result<(), MemFault> {
        if addr >= super::PROGRAM_BASE {
            return Err(MemFault::Unmapped);
        }
        let (s, o) = self.slice(addr).ok_or(MemFault::Unmapped)?;
        words(s, o, out)
    }

    #[inline]
    fn atominc(&mut self, index: u32) -> Result<u32, MemFault> {
        let g = self
            .globals
            .get_mut(index as usize)
            .ok_or(MemFault::NoGlobal)?;
        let old = *g;
        *g = old.wrapping_add(1);
        Ok(old)
    }
}
