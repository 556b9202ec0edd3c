//! The compressed 8-wide BVH (Ylitie, Karras and Laine 2017): 80-byte nodes with 8-bit
//! quantized child boxes, made from the BVH8 (identical partitioning).
