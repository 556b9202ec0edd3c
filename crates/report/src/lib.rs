//! `dualsplit report`: the paper's tables and figures, regenerated.
