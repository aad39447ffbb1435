//! Empty: a build script is what makes Cargo resolve the build-dependencies of Cargo.toml,
//! whose features are this crate's purpose there (see its comment).

fn main() {}
