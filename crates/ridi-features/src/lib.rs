//! Feature and target extraction for RIDI.
