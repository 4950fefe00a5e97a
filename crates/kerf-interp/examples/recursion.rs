//! Accumulated round-off of the recursive interpolator (paper 001) against direct evaluation,
//! next to plain forward differencing of the cubic Hermite segment with the same end data.
//!
//! Segments of the size of paper 001's example (a 3.5 m turbine blade): end points up to
//! 3.5 m apart, placed up to 2 m from the origin, tangents of the segment's size, seeded so
//! that every run prints the same table. For each step count, the largest tip deviation (mm,
//! Euclidean over x, y, z) over every step of every segment.
//!
//! Run: `cargo run --release -p kerf-interp --example recursion`

use kerf_interp::{max_deviation, CubicHermite, NewBasisSegment, Recurrence};

/// A small deterministic generator (64-bit LCG, top 53 bits).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next()
    }
}

fn main() {
    let segments = 20;
    let mut rng = Lcg(2024);
    let mut data = Vec::new();
    for _ in 0..segments {
        let q0: [f64; 5] = std::array::from_fn(|k| {
            if k < 3 {
                rng.range(-2000.0, 2000.0)
            } else {
                rng.range(-90.0, 90.0)
            }
        });
        let dir: [f64; 3] = std::array::from_fn(|_| rng.range(-1.0, 1.0));
        let n = (dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]).sqrt();
        let len = rng.range(1000.0, 3500.0);
        let q1: [f64; 5] = std::array::from_fn(|k| {
            if k < 3 {
                q0[k] + len * dir[k] / n
            } else {
                q0[k] + rng.range(-60.0, 60.0)
            }
        });
        let d0: [f64; 5] = std::array::from_fn(|k| (q1[k] - q0[k]) + rng.range(-0.5, 0.5) * len);
        let d1: [f64; 5] = std::array::from_fn(|k| (q1[k] - q0[k]) + rng.range(-0.5, 0.5) * len);
        data.push((q0, q1, d0, d1));
    }
    println!("| steps | three-term recurrence (paper 001) | Reinsch form | forward differences (cubic) |");
    println!("|---:|---:|---:|---:|");
    for steps in [600usize, 5_000, 1_000_000] {
        let (mut three, mut reinsch, mut fd) = (0.0f64, 0.0f64, 0.0f64);
        for (q0, q1, d0, d1) in &data {
            let nb = NewBasisSegment::hermite(*q0, *q1, *d0, *d1);
            let cu = CubicHermite::hermite(*q0, *q1, *d0, *d1);
            three = three.max(max_deviation(
                nb.steps(steps, Recurrence::ThreeTerm),
                steps,
                |t| nb.eval(t),
            ));
            reinsch = reinsch.max(max_deviation(
                nb.steps(steps, Recurrence::Reinsch),
                steps,
                |t| nb.eval(t),
            ));
            fd = fd.max(max_deviation(cu.forward_differences(steps), steps, |t| {
                cu.eval(t)
            }));
        }
        println!("| {steps} | {} | {} | {} |", um(three), um(reinsch), um(fd));
    }
}

fn um(mm: f64) -> String {
    format!("{:.3e} um", mm * 1000.0)
}
