//! RIDI in Rust: the layers of ridi-rs re-exported, and the end-to-end pipeline.

pub use ridi_correct as correct;
pub use ridi_data as data;
pub use ridi_eval as eval;
pub use ridi_features as features;
pub use ridi_frames as frames;
pub use ridi_regress as regress;
