//! One blending tolerance bounds both blends: the controller's (`G64 P`, `CTOL`) and the
//! planner's blend of curvature jumps in the set-points (with jerk limits). Independent truth:
//! the set-points' own deviation from the smooth path, which the motion measures on every
//! cycle, against the tolerance given.

use std::path::{Path, PathBuf};

use kerf_interp::Dialect;
use kerf_kinematics::Machine;
use kerf_pipeline::{plan_program, Job, MotionInput, MotionOptions};

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures")
        .join(name)
}

#[test]
fn a_smaller_blend_tolerance_bounds_the_set_points_and_the_program_alike() {
    // The gantry has jerk limits, so the planner blends the slots' line-arc junctions.
    let machine_file = fixture("machines/gantry_ac.json");
    let out = Job::from_files(fixture("sheet_metal_holes.json"), &machine_file)
        .expect("inputs")
        .run()
        .expect("job");
    let machine = Machine::read(&machine_file).expect("machine");
    let input = MotionInput::Toolpath(out.toolpath.clone());
    let mut deviations = Vec::new();
    for tol in [0.005, 0.001] {
        let opts = MotionOptions::default()
            .with_feed_mm_per_min(20000.0)
            .with_dialect(Some(Dialect::Linuxcnc))
            .with_blend_tolerance_mm(tol);
        let p = plan_program(&machine, &input, &opts, None).expect("plan");
        let dev = p.motion.blend_deviation();
        println!("blend tolerance {tol} mm: set-points within {dev:.2e} mm of the smooth path");
        assert!(dev > 0.0, "{tol}: the junctions are blended");
        assert!(dev <= tol * (1.0 + 1e-6), "{tol}: {dev} over the tolerance");
        let g = p.gcode_options().expect("dialect");
        assert_eq!(
            g.blend_tolerance_mm, tol,
            "the program's blending term is the same number"
        );
        let text = p.gcode().expect("gcode");
        assert!(
            text.contains(&format!("G64 P{tol}")),
            "{tol}: the controller is told the same tolerance"
        );
        deviations.push(dev);
    }
    assert!(
        deviations[1] < deviations[0],
        "smaller tolerance, smaller deviation: {deviations:?}"
    );
}
