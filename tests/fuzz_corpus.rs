//! Replays the kept fuzz corpus (`fuzz/corpus/<target>/`) and every crash reproducer
//! (`fuzz/regressions/<target>/`) through the same harnesses the `cargo fuzz` targets run
//! (`fuzz/src/lib.rs`, included here), so that what fuzzing found stays fixed without
//! libFuzzer or a nightly toolchain. A harness asserts more than "no panic": see its
//! documentation (round trips, sampled chord error within the tolerance, normals parallel to
//! the plane's, forward kinematics giving back every pose, a STEP import accepted only where
//! the parser accepts and giving a valid curves document).

#[allow(dead_code)]
#[path = "../fuzz/src/lib.rs"]
mod harness;

use std::path::Path;

use arbitrary::{Arbitrary, Unstructured};

/// Every file of the corpus and the reproducers of `target`.
fn inputs(target: &str) -> Vec<(String, Vec<u8>)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz");
    let mut out = Vec::new();
    for kind in ["corpus", "regressions"] {
        let Ok(entries) = std::fs::read_dir(root.join(kind).join(target)) else {
            continue;
        };
        for e in entries {
            let p = e.expect("dir entry").path();
            if p.is_file() {
                out.push((
                    p.display().to_string(),
                    std::fs::read(&p).expect("corpus file"),
                ));
            }
        }
    }
    out.sort();
    out
}

fn replay(target: &str, min: usize, run: impl Fn(&[u8])) {
    let all = inputs(target);
    assert!(
        all.len() >= min,
        "{target}: {} inputs kept, expected at least {min}",
        all.len()
    );
    for (name, bytes) in &all {
        // A panic names the input that caused it.
        let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| run(bytes)));
        assert!(result.is_ok(), "{target}: {name} fails its harness");
    }
}

fn structured<'a, T: Arbitrary<'a>>(bytes: &'a [u8]) -> Option<T> {
    T::arbitrary_take_rest(Unstructured::new(bytes)).ok()
}

#[test]
fn read_curves_corpus() {
    replay("read_curves", 10, harness::read_curves);
}

#[test]
fn read_toolpath_corpus() {
    replay("read_toolpath", 10, harness::read_toolpath);
}

#[test]
fn read_axes_corpus() {
    replay("read_axes", 10, harness::read_axes);
}

#[test]
fn read_machine_corpus() {
    replay("read_machine", 10, harness::read_machine);
}

#[test]
fn read_stl_corpus() {
    replay("read_stl", 10, harness::read_stl);
}

#[test]
fn discretize_corpus() {
    replay("discretize", 10, |b| {
        if let Some(case) = structured::<harness::CurveCase>(b) {
            harness::discretize(&case);
        }
    });
}

#[test]
fn normals_corpus() {
    replay("normals", 10, |b| {
        if let Some(case) = structured::<harness::SurfaceCase>(b) {
            harness::normals(&case);
        }
    });
}

#[test]
fn kinematics_corpus() {
    replay("kinematics", 10, |b| {
        if let Some(case) = structured::<harness::MachineCase>(b) {
            harness::kinematics(&case);
        }
    });
}

#[test]
fn step_syntax_corpus() {
    replay("step_syntax", 10, harness::step_syntax);
}

#[test]
fn step_import_corpus() {
    replay("step_import", 10, harness::step_import);
}

#[test]
fn iges_import_corpus() {
    replay("iges_import", 8, harness::iges_import);
}
