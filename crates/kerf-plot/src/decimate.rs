//! Bounding what a picture draws, so that its size does not grow with the input's.
//!
//! A 600-byte circle cut at `-t 1e-8` has 594,000 cutting points; drawn one circle and one
//! polyline vertex per point in four views, plus a dot per segment in the chord chart and five
//! axis rows, its `plot.svg` was 233 MB. [`bounded`] keeps at most [`MAX_DRAWN_SEGMENTS`]
//! segments (every `k`-th cutting point of each path, both ends kept), [`MAX_DRAWN_PATHS`]
//! paths, [`MAX_DRAWN_CURVE_SAMPLES`] curve samples and as many axis positions, and says what it
//! left out in a line the picture shows. A drawn segment that stands for several carries the
//! largest of their chord errors, so a segment above the tolerance still shows red.

use std::borrow::Cow;

use crate::scene::{AxesChart, CutPicture, PathPicture, ProcessPicture, Scene};

/// The most chord segments drawn over all paths (each view draws them and their points).
pub const MAX_DRAWN_SEGMENTS: usize = 20_000;
/// The most paths drawn (the first ones, in toolpath order).
pub const MAX_DRAWN_PATHS: usize = 2_000;
/// The most curve samples drawn over all paths, and the most axis positions charted.
pub const MAX_DRAWN_CURVE_SAMPLES: usize = 20_000;

/// In a thinned picture, the most head-check bands drawn (the first ones in cutting order).
const MAX_DRAWN_BANDS: usize = 200;

/// In a thinned picture, about the most points of the head-check bands in all (each band
/// keeps its two ends besides).
const MAX_DRAWN_BAND_POINTS: usize = 5_000;

/// `scene` as drawn: itself when it is within the limits, else a reduced copy, with the line
/// that says what was left out.
pub(crate) fn bounded(scene: &Scene) -> (Cow<'_, Scene>, Option<String>) {
    let segments: usize = scene.paths.iter().map(|p| p.segment_errors.len()).sum();
    let samples: usize = scene.paths.iter().map(|p| p.curve.len()).sum();
    let positions: usize = scene
        .axes
        .as_ref()
        .map_or(0, |a| a.paths.iter().map(|(_, p)| p.len()).sum::<usize>());
    if segments <= MAX_DRAWN_SEGMENTS
        && scene.paths.len() <= MAX_DRAWN_PATHS
        && samples <= MAX_DRAWN_CURVE_SAMPLES
        && positions <= MAX_DRAWN_CURVE_SAMPLES
    {
        return (Cow::Borrowed(scene), None);
    }
    let kept = &scene.paths[..scene.paths.len().min(MAX_DRAWN_PATHS)];
    let kept_segments: usize = kept.iter().map(|p| p.segment_errors.len()).sum();
    let kept_samples: usize = kept.iter().map(|p| p.curve.len()).sum();
    let step = kept_segments.div_ceil(MAX_DRAWN_SEGMENTS).max(1);
    let sample_step = kept_samples.div_ceil(MAX_DRAWN_CURVE_SAMPLES).max(1);
    let paths: Vec<PathPicture> = kept
        .iter()
        .map(|p| thin_path(p, step, sample_step))
        .collect();
    let ids: Vec<&str> = paths.iter().map(|p| p.id.as_str()).collect();
    let process = scene.process.as_ref().map(|pr| {
        let mut cuts: Vec<CutPicture> = pr
            .cuts
            .iter()
            .filter(|c| ids.contains(&c.id.as_str()))
            .cloned()
            .collect();
        thin_bands(&mut cuts);
        ProcessPicture {
            cuts,
            traverses: pr.traverses.iter().take(MAX_DRAWN_PATHS).cloned().collect(),
        }
    });
    let axes = scene.axes.as_ref().map(|a| {
        let step = positions.div_ceil(MAX_DRAWN_CURVE_SAMPLES).max(1);
        AxesChart {
            paths: a
                .paths
                .iter()
                .take(MAX_DRAWN_PATHS)
                .map(|(id, p)| (id.clone(), every(p, step)))
                .collect(),
            ..a.clone()
        }
    });
    let drawn: usize = paths.iter().map(|p| p.segment_errors.len()).sum();
    let mut note = format!(
        "Drawn: {drawn} of {segments} segments (1 in {step} cutting points of each path, its \
         ends kept; a drawn segment shows the largest chord error of those it stands for)"
    );
    if paths.len() < scene.paths.len() {
        note.push_str(&format!(
            "; the first {} of {} paths",
            paths.len(),
            scene.paths.len()
        ));
    }
    note.push_str(". The toolpath and axes files hold every point.");
    let reduced = Scene {
        title: scene.title.clone(),
        subtitle: scene.subtitle.clone(),
        tolerance: scene.tolerance,
        paths,
        axes,
        process,
    };
    (Cow::Owned(reduced), Some(note))
}

/// The head check's bands of the drawn `cuts`, bounded: the first [`MAX_DRAWN_BANDS`] bands
/// in cutting order (the others dropped), each thinned to every `k`-th point (its ends kept)
/// with `k` such that they hold about [`MAX_DRAWN_BAND_POINTS`] points in all (at most that
/// and their two ends each).
fn thin_bands(cuts: &mut [CutPicture]) {
    let mut left = MAX_DRAWN_BANDS;
    let mut points = 0usize;
    for c in cuts.iter_mut() {
        for bands in [&mut c.head_tilted, &mut c.head_close] {
            bands.truncate(left);
            left -= bands.len();
            points += bands.iter().map(Vec::len).sum::<usize>();
        }
    }
    let step = points.div_ceil(MAX_DRAWN_BAND_POINTS).max(1);
    for c in cuts.iter_mut() {
        for bands in [&mut c.head_tilted, &mut c.head_close] {
            for b in bands.iter_mut() {
                *b = every(b, step);
            }
        }
    }
}

/// Every `step`-th item of `items`, the last always kept.
fn every<T: Clone>(items: &[T], step: usize) -> Vec<T> {
    let mut out: Vec<T> = items.iter().step_by(step).cloned().collect();
    if items.len() > 1 && (items.len() - 1) % step != 0 {
        out.extend(items.last().cloned());
    }
    out
}

/// `p` with every `step`-th cutting point (ends kept) and every `sample_step`-th curve sample;
/// each kept segment carries the largest error of the segments it replaces.
fn thin_path(p: &PathPicture, step: usize, sample_step: usize) -> PathPicture {
    let n = p.points.len();
    let mut idx: Vec<usize> = (0..n).step_by(step).collect();
    if n > 1 && (n - 1) % step != 0 {
        idx.push(n - 1);
    }
    let segment_errors = idx
        .windows(2)
        .map(|w| {
            p.segment_errors[w[0]..w[1].min(p.segment_errors.len())]
                .iter()
                .copied()
                .fold(
                    0.0,
                    |m: f64, e| if e.is_nan() { f64::NAN } else { m.max(e) },
                )
        })
        .collect();
    PathPicture {
        id: p.id.clone(),
        curve: every(&p.curve, sample_step),
        points: idx.iter().map(|&i| p.points[i]).collect(),
        normals: p
            .normals
            .as_ref()
            .map(|v| idx.iter().filter_map(|&i| v.get(i).copied()).collect()),
        segment_errors,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Point3;

    fn path(id: &str, n: usize) -> PathPicture {
        let pts: Vec<Point3<f64>> = (0..n).map(|i| Point3::new(i as f64, 0.0, 0.0)).collect();
        let mut errors = vec![0.001; n.saturating_sub(1)];
        if n > 10 {
            errors[n / 2] = 0.5; // one segment far above the tolerance
        }
        PathPicture {
            id: id.into(),
            curve: pts.clone(),
            points: pts,
            normals: None,
            segment_errors: errors,
        }
    }

    #[test]
    fn a_small_scene_is_drawn_whole() {
        let scene = Scene {
            title: String::new(),
            subtitle: String::new(),
            tolerance: 0.01,
            paths: vec![path("a", 100)],
            axes: None,
            process: None,
        };
        let (s, note) = bounded(&scene);
        assert!(matches!(s, Cow::Borrowed(_)) && note.is_none(), "untouched");
    }

    #[test]
    fn thinning_keeps_the_ends_and_the_worst_error() {
        let p = thin_path(&path("a", 1001), 7, 3);
        assert_eq!(p.points.first(), Some(&Point3::new(0.0, 0.0, 0.0)), "first");
        assert_eq!(
            p.points.last(),
            Some(&Point3::new(1000.0, 0.0, 0.0)),
            "last"
        );
        assert_eq!(
            p.segment_errors.len() + 1,
            p.points.len(),
            "one error per segment"
        );
        let worst = p.segment_errors.iter().copied().fold(0.0, f64::max);
        assert_eq!(worst, 0.5, "the segment above the tolerance still shows");
        assert_eq!(
            p.curve.last(),
            Some(&Point3::new(1000.0, 0.0, 0.0)),
            "curve end"
        );
    }
}
