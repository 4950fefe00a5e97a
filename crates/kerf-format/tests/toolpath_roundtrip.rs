//! Property: any valid toolpath, written and read back, is bit-for-bit the same.

use kerf_format::toolpath::{self, ToolpathFile, ToolpathPoints, ToolpathRecord};
use kerf_format::Units;
use proptest::prelude::*;

/// Finite doubles of every magnitude, subnormals included.
fn finite() -> impl Strategy<Value = f64> {
    prop_oneof![
        any::<f64>().prop_filter("finite", |x| x.is_finite()),
        -1e3..1e3f64,
    ]
}

fn path(index: usize, normals: bool) -> impl Strategy<Value = ToolpathRecord> {
    (2usize..40)
        .prop_flat_map(move |n| {
            (
                prop::collection::vec(finite(), n),
                prop::collection::vec([finite(), finite(), finite()], n),
                prop::collection::vec([-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64], n),
                0.0..1e-3f64,
            )
        })
        .prop_filter_map("distinct params", move |(mut params, xyz, dirs, err)| {
            params.sort_by(f64::total_cmp);
            params.dedup(); // by ==, so -0.0 and 0.0 count as one
            if params.len() < 2 {
                return None;
            }
            let n = params.len();
            let points = if normals {
                let mut poses = Vec::with_capacity(n);
                for (p, d) in xyz.iter().zip(&dirs).take(n) {
                    let norm = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                    if norm < 1e-3 {
                        return None;
                    }
                    poses.push([p[0], p[1], p[2], d[0] / norm, d[1] / norm, d[2] / norm]);
                }
                ToolpathPoints::Poses(poses)
            } else {
                ToolpathPoints::Positions(xyz[..n].to_vec())
            };
            Some(ToolpathRecord {
                id: format!("path-{index}"),
                params,
                points,
                max_chord_error: err,
                kerf_offset: None,
            })
        })
}

proptest! {
    #[test]
    fn write_then_read_is_the_identity(a in path(0, true), b in path(1, false)) {
        let file = ToolpathFile { units: Units::Millimetres, tolerance: 1e-3, paths: vec![a, b] };
        let text = toolpath::to_string(&file).expect("valid toolpath");
        let back = toolpath::from_str(&text).expect("reads back");
        prop_assert_eq!(back, file);
    }
}
