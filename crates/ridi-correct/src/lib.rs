//! Acceleration-bias correction and integration for RIDI.
