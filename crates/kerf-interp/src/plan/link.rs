//! Joining the paths of a program with rapid (laser-off) moves.

use kerf_kinematics::Axes;

use crate::block::{Block, Station};
use crate::model::AxisModel;

/// Joins the blocks of several paths into one program: between the end of one path and the
/// start of the next, a rapid (laser-off) line, planned at the axes' own limits.
pub fn link_paths(paths: Vec<Vec<Block>>) -> Vec<Block> {
    link(paths, |_, last, first| {
        if last.end_axes == first.start_axes {
            return Vec::new();
        }
        let b = Station {
            tip: first.start_tip(),
            axis: first.end_tool_axis,
            param: None,
            axes: first.start_axes,
        };
        vec![end_station(last), b]
    })
}

/// Like [`link_paths`], but each rapid move backs off `retract` mm along the tool axis from
/// the end of one path (rotary axes standing), traverses to `retract` mm above the next path's
/// start along its tool axis, and approaches it along that axis, so the nozzle leaves and
/// meets the part along the beam instead of crossing it at cutting height. The traverse between
/// the two retract points is one straight move of the machine axes (the rotary axes turn during
/// it): it clears the part only if the retract distance is large enough for the part's shape;
/// nothing here checks the traverse against the part. With `retract <= 0` it is one straight rapid
/// (as [`link_paths`], but arriving with the next path's start orientation).
pub fn link_paths_with_retract<M: AxisModel + ?Sized>(
    model: &M,
    paths: Vec<Vec<Block>>,
    retract: f64,
) -> Vec<Block> {
    link(paths, |_, last, first| {
        retract_stops(model, last, first, retract)
    })
}

/// Like [`link_paths_with_retract`], but the rapid moves between path `k` and path `k + 1` run
/// through the given waypoints `traverses[k]` (tip, tool axis and axes `[X, Y, Z, tilt, C]`
/// of each, e.g. a traverse checked against the part by `kerf-process`): from the end of
/// path `k` to the first waypoint, from one waypoint to the next, and from the last to the
/// start of path `k + 1`, each one rapid line. A gap without waypoints (a missing or empty
/// entry) falls back to the retract of [`link_paths_with_retract`].
pub fn link_paths_through<M: AxisModel + ?Sized>(
    model: &M,
    paths: Vec<Vec<Block>>,
    traverses: &[Vec<Station>],
    retract: f64,
) -> Vec<Block> {
    link(paths, |k, last, first| {
        let Some(way) = traverses.get(k).filter(|w| !w.is_empty()) else {
            return retract_stops(model, last, first, retract);
        };
        let start = Station {
            tip: first.start_tip(),
            axis: model.tool_axis(first.start_axes.tilt, first.start_axes.c),
            param: None,
            axes: first.start_axes,
        };
        let mut stops = vec![end_station(last)];
        stops.extend(way.iter().map(|s| Station { param: None, ..*s }));
        stops.push(start);
        stops
    })
}

/// The station where `last` ends, with its own tool axis there.
fn end_station(last: &Block) -> Station {
    Station {
        tip: last.end_tip(),
        axis: last.end_tool_axis,
        param: None,
        axes: last.end_axes,
    }
}

/// The one loop of the three linkers: the paths' blocks in order (empty paths left out), and
/// between two paths a rapid line from each stop `gap(k, last, first)` gives to the next (`k`
/// counts the gaps from 0; no stops, no rapid).
fn link(
    paths: Vec<Vec<Block>>,
    mut gap: impl FnMut(usize, &Block, &Block) -> Vec<Station>,
) -> Vec<Block> {
    let mut out: Vec<Block> = Vec::new();
    let mut k = 0usize;
    for blocks in paths {
        let Some(first) = blocks.first() else {
            continue;
        };
        if let Some(last) = out.last() {
            let stops = gap(k, last, first);
            k += 1;
            for w in stops.windows(2) {
                let mut rapid = Block::line(&w[0], &w[1]);
                rapid.rapid = true;
                rapid.path = first.path;
                rapid.stations = [0, 0];
                out.push(rapid);
            }
        }
        out.extend(blocks);
    }
    out
}

/// The stops of [`link_paths_with_retract`]'s rapid from `last`'s end to `first`'s start: up
/// `retract` mm along the end's tool axis, over to `retract` mm above the start along its tool
/// axis and down (straight across for `retract <= 0` or NaN), the tool axes the model's at
/// both ends; none where the axes already stand at the start.
fn retract_stops<M: AxisModel + ?Sized>(
    model: &M,
    last: &Block,
    first: &Block,
    retract: f64,
) -> Vec<Station> {
    if last.end_axes == first.start_axes {
        return Vec::new();
    }
    let retract = if retract.is_nan() {
        0.0
    } else {
        retract.max(0.0)
    };
    let station = |tip: nalgebra::Point3<f64>, axes: Axes| {
        let axis = model.tool_axis(axes.tilt, axes.c);
        let lin = model.linear_axes(&tip, axes.tilt, axes.c);
        Station {
            tip,
            axis,
            param: None,
            axes: Axes::new(lin[0], lin[1], lin[2], axes.tilt, axes.c),
        }
    };
    let end = station(last.end_tip(), last.end_axes);
    let start = station(first.start_tip(), first.start_axes);
    if retract > 0.0 {
        let up = station(end.tip + end.axis * retract, end.axes);
        let over = station(start.tip + start.axis * retract, start.axes);
        vec![end, up, over, start]
    } else {
        vec![end, start]
    }
}
