//! The quantized dual-split tree: the DST's planes as k-bit offsets inside a local frame,
//! several DST levels collapsed into one fetch (Lin et al. 2020, §5, future work).
