//! Cascaded placement classification and velocity regression for RIDI.
