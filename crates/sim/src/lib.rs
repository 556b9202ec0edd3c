//! A TRaX-style many-core simulator with the dual-split pipeline.
