//! Placeholder bench.

fn main() {}
