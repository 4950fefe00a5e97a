//! Per-stage timings (`report.json`'s `timings`). One test in its own process: the process's CPU
//! clock counts every thread, so no other test may run beside it.

mod common;

use std::time::{Duration, Instant};

use common::fixture;
use kerf_pipeline::{process_cpu_time, Job, Lap, Timings};

#[test]
fn stages_are_timed_in_order_and_cpu_time_counts_work_not_waiting() {
    // The clock: a sleep costs wall time and next to no CPU; a loop that runs until the CPU
    // clock has advanced 50 ms is timed at least that (counted work, not a wall-clock guess).
    let mut t = Timings::default();
    t.time("sleep", || std::thread::sleep(Duration::from_millis(100)));
    let mut lap = Lap::start();
    let c0 = process_cpu_time();
    let wall = Instant::now();
    let mut x = 0u64;
    while process_cpu_time() - c0 < Duration::from_millis(50) && wall.elapsed().as_secs() < 60 {
        x = x.wrapping_mul(6364136223846793005).wrapping_add(1);
    }
    std::hint::black_box(x);
    lap.split(&mut t, "busy");
    let (sleep, busy) = (&t.stages[0], &t.stages[1]);
    assert!(sleep.wall_s >= 0.1 && sleep.cpu_s < 0.05, "{sleep:?}");
    assert!(
        busy.cpu_s >= 0.05 && busy.wall_s >= busy.cpu_s * 0.99,
        "{busy:?}"
    );
    // Adding to a stage sums; merging sums stage by stage.
    let mut u = t.clone();
    u.merge(&t);
    assert_eq!(u.stages.len(), 2, "{u:?}");
    assert!((u.cpu_s() - 2.0 * t.cpu_s()).abs() < 1e-12, "{u:?}");

    // A run: every stage in the order it ran, each total the sum of its stages, and the stages
    // within the time measured around the whole run (the CPU total counts both cores).
    let job = Job::from_files(fixture("dome.json"), fixture("machines/ac_head.json")).expect("job");
    let (w0, c0) = (Instant::now(), process_cpu_time());
    let out = job.run().expect("run");
    let (wall, cpu) = (
        w0.elapsed().as_secs_f64(),
        (process_cpu_time() - c0).as_secs_f64(),
    );
    let names: Vec<&str> = out.report.timings.stages.iter().map(|s| s.stage).collect();
    assert_eq!(
        names,
        [
            "discretize",
            "normals",
            "sides",
            "place",
            "cuts",
            "kinematics",
            "head",
            "traverses",
            "plan",
            "gcode",
            "view",
            "report"
        ],
        "stages in order"
    );
    assert!(out.report.timings.wall_s() <= wall && out.report.timings.cpu_s() <= cpu + 1e-3);
    // As `report.json` has them.
    let report = serde_json::to_value(&out.report).expect("the report as JSON");
    let r = &report["timings"];
    let stages = r["stages"].as_array().expect("stages");
    assert_eq!(stages.len(), names.len());
    let sum: f64 = stages
        .iter()
        .map(|s| s["cpu_s"].as_f64().expect("cpu"))
        .sum();
    assert!(
        (sum - r["cpu_s"].as_f64().expect("total")).abs() < 1e-9,
        "{r}"
    );
    // Written: `report.json` adds the write of the files before it; reading comes first.
    let dir = tempfile::tempdir().expect("tempdir");
    let mut out = out;
    let mut read = Timings::default();
    read.add("read", 0.25, 0.125);
    out.prepend_timings(read);
    out.write_dir(dir.path()).expect("write");
    let text = std::fs::read_to_string(dir.path().join("report.json")).expect("report");
    let report: serde_json::Value = serde_json::from_str(&text).expect("json");
    let stages = report["timings"]["stages"].as_array().expect("stages");
    assert_eq!(stages[0]["stage"], "read");
    assert_eq!(stages[0]["cpu_s"], 0.125);
    assert_eq!(stages[stages.len() - 1]["stage"], "write");
    assert_eq!(stages.len(), names.len() + 2);
}
