//! Host package for the end-to-end tests in `tests/` (and, in `src/main.rs`, the root's `cargo run`,
//! which opens the editor); it has no code of its own.
