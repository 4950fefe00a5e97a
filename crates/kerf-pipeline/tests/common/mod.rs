//! Helpers shared by the pipeline's tests: the fixtures and the shipped AC-head machine.

#![allow(dead_code)] // each test file uses its own subset

use std::path::{Path, PathBuf};

use kerf_kinematics::Machine;

/// A file under `fixtures/`.
pub(crate) fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures")
        .join(name)
}

/// `fixtures/machines/ac_head.json`.
pub(crate) fn machine() -> Machine {
    Machine::read(fixture("machines/ac_head.json")).expect("machine")
}
