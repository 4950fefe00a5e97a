//! The traverses between the cuts of one set-up (stage 3e of [`crate::Job::run`]): each gap
//! between two cuts routed and checked against the set-up's surfaces
//! ([`kerf_process::plan_rapids`]), written into the axes document, turned into the
//! interpolator's stations and the picture's lines; a gap no route clears falls back to the
//! unchecked retract, straight move and approach, with a warning. [`Tally`] keeps what the
//! report's `traverses` section says about every set-up.

use std::path::Path;

use kerf_format::CurvesFile;
use kerf_interp::Station;
use kerf_kinematics::{Axes, AxesFile, AxesMove, Head, Machine, SolvedPath};
use kerf_process::{Gap, HeadCheckOptions, Obstacles, Pose, Route, TraverseHead, TraverseOptions};
use nalgebra::Point3;

use crate::cuts::CutPath;
use crate::error::Result;
use crate::place::Placed;
use crate::report::{OwnSurfaces, SearchedTraverse, TraversesReport, UncheckedTraverse};

/// What the traverses of every set-up came to, for the report.
#[derive(Debug, Default)]
pub(crate) struct Tally {
    /// Each checked traverse.
    checked: Vec<Checked>,
    /// The gaps no route cleared.
    unchecked: Vec<UncheckedTraverse>,
    /// Gaps where a cut's own surface comes back over the head line.
    own: Vec<OwnSurfaces>,
    /// Gaps a search around the part cleared.
    searched: Vec<SearchedTraverse>,
    /// The clearance the head model kept along the traverses, mm (with the head check).
    head_clearance_mm: Option<f64>,
    /// Traverses no route cleared the head on, taken (head collisions accepted).
    head_too_close: usize,
}

/// What the report keeps of one checked traverse.
#[derive(Debug)]
struct Checked {
    /// Its route's shape.
    route: Route,
    /// The route's length, mm.
    length_mm: f64,
    /// The least distance from the part proven for the route and the machine's moves, mm.
    min_distance_mm: f64,
    /// The least distance proven between the head model and the part along the moves, mm
    /// (with the head check).
    head_min_distance_mm: Option<f64>,
    /// The machine's moves split so that they clear.
    split_moves: usize,
    /// The surfaces left out of its check.
    absent: Vec<String>,
}

/// The traverses of one set-up.
pub(crate) struct SetupTraverses {
    /// Per gap between consecutive cuts of the set-up, the checked route as the interpolator's
    /// stations (empty: the unchecked retract traverse); empty without traverse options.
    pub(crate) stations: Vec<Vec<Station>>,
    /// Per gap, the traverse's line for the picture (part coordinates).
    pub(crate) plot: Vec<Vec<Point3<f64>>>,
    /// A warning per gap that fell back to the unchecked traverse.
    pub(crate) warnings: Vec<String>,
}

/// The head check of the traverses (with the cuts' head check).
pub(crate) struct HeadAlong<'a> {
    /// The machine's head.
    pub(crate) head: &'a Head,
    /// The cuts' head check options (the cutting clearance).
    pub(crate) opts: HeadCheckOptions,
    /// A traverse whose head no route clears is a warning, not a refusal.
    pub(crate) accept: bool,
    /// Every surface of the file placed with the set-up (the head check's).
    pub(crate) obstacles: &'a Obstacles,
    /// The part of each of `obstacles`.
    pub(crate) parts: &'a [usize],
}

/// The set-up's cuts and where they come from.
pub(crate) struct SetupCuts<'a> {
    /// The curves file (ids, named surfaces).
    pub(crate) file: &'a CurvesFile,
    /// The input's path, for errors.
    pub(crate) path: Option<&'a Path>,
    /// The placement of every path.
    pub(crate) placed: &'a Placed,
    /// Every cut, in cutting order.
    pub(crate) cuts: &'a [CutPath],
    /// Every cut solved to machine axes.
    pub(crate) solved: &'a [SolvedPath],
    /// The set-up's index.
    pub(crate) setup: usize,
    /// Indices (into `cuts` and `solved`) of the set-up's cuts, in order.
    pub(crate) in_setup: &'a [usize],
}

/// Routes and checks the traverses of one set-up ([`SetupCuts`]) with `opts` (`None`: none
/// checked, no stations), writing each checked route into `axes` and its figures into
/// `tally`. The unchecked fallback's picture rises `retract_mm` along the tool axes.
///
/// # Errors
/// [`crate::Error::Process`] if the set-up's surfaces cannot be placed as obstacles.
pub(crate) fn route_setup(
    s: &SetupCuts<'_>,
    machine: &Machine,
    opts: Option<&TraverseOptions>,
    head: Option<&HeadAlong<'_>>,
    retract_mm: f64,
    axes: &mut AxesFile,
    tally: &mut Tally,
) -> Result<SetupTraverses> {
    let mut out = SetupTraverses {
        stations: Vec::new(),
        plot: Vec::new(),
        warnings: Vec::new(),
    };
    let (Some(opts), Some(&first)) = (opts, s.in_setup.first()) else {
        return Ok(out);
    };
    let (file, cuts, solved) = (s.file, s.cuts, s.solved);
    let placement = s.placed.placement_of(cuts[first].curve);
    // The surfaces the set-up's curves name, placed with it.
    let obs = Obstacles::from_file(file, &s.placed.plan.setups[s.setup].paths, |p| {
        placement.apply_point(p)
    })
    .map_err(|source| crate::Error::Process {
        file: s.path.map(Path::to_path_buf),
        source,
    })?;
    // With the head check: the head model along every route too, against every surface of the
    // parts the gap's cuts lie on (a wall beside a hole, which no curve names).
    tally.head_clearance_mm = head.map(|h| h.opts.clearance_mm);
    let traverse_head = head.map(|h| TraverseHead::new(h.head, h.opts, h.obstacles, h.parts));
    let limits = machine.limits.map(|r| r.map(|r| (r.min, r.max)));
    let gaps: Vec<Gap> = s
        .in_setup
        .windows(2)
        .map(|w| gap(file, cuts, solved, w[0], w[1]))
        .collect();
    let rapids = kerf_process::plan_rapids(
        machine.kinematics.as_ref(),
        &limits,
        &obs,
        &gaps,
        opts,
        traverse_head.as_ref(),
    );
    let cut_end = |k: usize| cuts[k].poses[cuts[k].poses.len() - 1];
    for ((w, planned), gap) in s.in_setup.windows(2).zip(&rapids).zip(&gaps) {
        let (after, before) = (&solved[w[0]].id, &solved[w[1]].id);
        let (t, r, absent) = match planned {
            Ok(p) => p,
            Err(e) => {
                // No checked route: the unchecked retract traverse, said loudly
                // (`Output::warnings`, and `traverses.unchecked` in the report).
                out.warnings
                    .push(format!("{e}; this traverse is NOT checked"));
                // The surfaces the routes were checked without (the last attempt leaves out
                // all those in the cuts' way).
                tally.unchecked.push(UncheckedTraverse {
                    after: after.clone(),
                    before: before.clone(),
                    reason: e.to_string(),
                    surfaces_left_out: kerf_process::in_the_cuts_way(&obs, gap, opts),
                });
                out.stations.push(Vec::new());
                // The plot: the unchecked retract, straight move and approach.
                let up = |q: &Pose, r: f64| q.position + q.axis * r;
                let (ea, pb) = (cut_end(w[0]), &cuts[w[1]].poses[0]);
                out.plot.push(vec![
                    up(&ea, 0.0),
                    up(&ea, retract_mm),
                    up(pb, retract_mm),
                    up(pb, 0.0),
                ]);
                continue;
            }
        };
        if let Some(close) = &r.head_too_close {
            // The tip and the nozzle line clear, the head on no route: refused, or taken with
            // a warning where head collisions are accepted.
            let reason = format!(
                "on every route whose tip and nozzle keep the traverse clearance, the head comes {close} (cutting clearance {} mm; the first route it was tried on, or where it stands at a cut's end or at every retract height)",
                head.map_or(0.0, |h| h.opts.clearance_mm),
            );
            if !head.is_some_and(|h| h.accept) {
                return Err(crate::Error::Process {
                    file: s.path.map(Path::to_path_buf),
                    source: kerf_process::ProcessError::TraverseHeadTooClose {
                        after: after.clone(),
                        before: before.clone(),
                        reason: format!("{reason}{}", crate::head::WAYS_OUT),
                    },
                });
            }
            let e = kerf_process::ProcessError::TraverseHeadTooClose {
                after: after.clone(),
                before: before.clone(),
                reason: format!(
                    "{reason}; the route taken is checked for its tip and nozzle line only"
                ),
            };
            out.warnings
                .push(format!("{e} (accepted: accept_head_collisions)"));
            tally.head_too_close += 1;
        }
        axes.paths[w[1]].traverse = Some(AxesMove {
            positions: r.axes.iter().map(Axes::to_array).collect(),
            poses: r.poses.iter().map(Pose::to_array).collect(),
        });
        out.stations.push(stations(r));
        // Surfaces left out that a neighbouring cut names itself: its own surface curls over
        // its head line (the cut meets it, whatever the traverse does).
        let over = kerf_process::own_surfaces_over_the_head(&obs, gap, opts);
        let own: Vec<String> = absent
            .iter()
            .filter(|id| over.contains(id))
            .cloned()
            .collect();
        if !own.is_empty() {
            tally.own.push(OwnSurfaces {
                after: after.clone(),
                before: before.clone(),
                surfaces: own,
            });
        }
        if t.route == Route::Searched {
            tally.searched.push(SearchedTraverse {
                after: after.clone(),
                before: before.clone(),
                waypoints: t.waypoints.len(),
                length_mm: t.length_mm,
                surfaces_left_out: absent.clone(),
            });
        }
        tally.checked.push(Checked {
            route: t.route,
            length_mm: t.length_mm,
            min_distance_mm: t.min_distance_mm.min(r.min_distance_mm),
            head_min_distance_mm: r.head_min_distance_mm,
            split_moves: r.split_moves,
            absent: absent.clone(),
        });
        // The plot: the checked traverse back in part coordinates.
        let (rot, shift) = (placement.rotation(), placement.translation_mm);
        let part = |q: &Pose| Point3::from(rot.inverse() * (q.position - shift).coords);
        let (ea, pb) = (cut_end(w[0]), cuts[w[1]].poses[0]);
        let mut line = vec![ea.position];
        line.extend(r.poses.iter().map(part));
        line.push(pb.position);
        out.plot.push(line);
    }
    Ok(out)
}

/// The interpolator's stations of a traverse's rapid waypoints (no curve parameters).
fn stations(r: &kerf_process::RapidMoves) -> Vec<Station> {
    r.axes
        .iter()
        .zip(&r.poses)
        .map(|(a, p)| Station {
            tip: p.position,
            axis: p.axis,
            param: None,
            axes: *a,
        })
        .collect()
}

/// The gap from cut `a` to cut `b`: the end and start poses with their axes, the contour's
/// own end and start (where the head meets the part whatever the traverse does), and the
/// surfaces the two curves name.
fn gap(file: &CurvesFile, cuts: &[CutPath], solved: &[SolvedPath], a: usize, b: usize) -> Gap {
    let (sa, sb) = (&solved[a], &solved[b]);
    // The solved pose of a cut's k-th pose (lead-in, contour, lead-out).
    let at = |s: &SolvedPath, k: usize| {
        let j = s.source.iter().position(|v| *v == Some(k)).unwrap_or(0);
        s.poses[j].position
    };
    let [m, c, _] = cuts[a].counts;
    Gap {
        from: sa.poses[sa.poses.len() - 1],
        from_axes: sa.axes[sa.axes.len() - 1],
        to: sb.poses[0],
        to_axes: sb.axes[0],
        from_contour: at(sa, m + c - 1),
        to_contour: at(sb, cuts[b].counts[0]),
        from_surfaces: file.curves[cuts[a].curve].surfaces.clone(),
        to_surfaces: file.curves[cuts[b].curve].surfaces.clone(),
    }
}

impl Tally {
    /// The `traverses` object of `report.json`: how the traverses between cuts were checked
    /// against the part and what they came to.
    pub(crate) fn report(self, opts: Option<&TraverseOptions>) -> TraversesReport {
        let Tally {
            checked: rapids,
            unchecked: blocked,
            own,
            searched,
            head_clearance_mm,
            head_too_close,
        } = self;
        let mut unchecked: Vec<String> = Vec::new();
        for Checked { absent, .. } in &rapids {
            for id in absent {
                if !unchecked.contains(id) {
                    unchecked.push(id.clone());
                }
            }
        }
        // How many traverses took each route.
        let routes: std::collections::BTreeMap<String, usize> = [
            Route::Straight,
            Route::Lifted,
            Route::SafePlane,
            Route::Searched,
        ]
        .iter()
        .map(|k| {
            let n = rapids.iter().filter(|c| c.route == *k).count();
            (k.name().to_string(), n)
        })
        .collect();
        let Some(o) = opts else {
            return TraversesReport {
                checked: false,
                clearance_mm: None,
                retract_mm: None,
                nozzle_mm: None,
                count: None,
                checked_count: None,
                unchecked: None,
                lifted: None,
                routes: None,
                searched: None,
                split_moves: None,
                length_mm: None,
                min_distance_mm: None,
                head_clearance_mm: None,
                head_min_distance_mm: None,
                head_too_close: None,
                head_note: None,
                surfaces_in_the_cuts_way: None,
                surfaces_note: None,
                own_surface_over_the_head: None,
                unchecked_note: None,
                searched_note: None,
                note: Some("no traverse options (a clearance of 0): retract along the tool axis, one straight move, approach; not checked against the part".into()),
            };
        };
        TraversesReport {
            checked: true,
            clearance_mm: Some(o.clearance_mm),
            retract_mm: Some(o.retract_mm),
            nozzle_mm: Some(o.nozzle_mm),
            count: Some(rapids.len() + blocked.len()),
            checked_count: Some(rapids.len()),
            unchecked: Some(blocked),
            lifted: Some(rapids.iter().filter(|c| c.route != Route::Straight).count()),
            routes: Some(routes),
            searched: Some(searched),
            split_moves: Some(rapids.iter().map(|c| c.split_moves).sum::<usize>()),
            length_mm: Some(rapids.iter().map(|c| c.length_mm).sum::<f64>()),
            min_distance_mm: Some(rapids.iter().map(|c| c.min_distance_mm).fold(f64::INFINITY, f64::min)),
            head_clearance_mm,
            // Absent where no traverse cleared the head (none, or every one too close).
            head_min_distance_mm: head_clearance_mm.and_then(|_| {
                rapids
                    .iter()
                    .filter_map(|c| c.head_min_distance_mm)
                    .reduce(f64::min)
            }),
            head_too_close: head_clearance_mm.map(|_| head_too_close),
            head_note: head_clearance_mm.map(|_| "the head model (head.paths' solids) checked along every checked traverse as along the cuts: the machine's moves from a cut's end through the waypoints to the next pierce, against every surface of the parts the two cuts lie on (those in the cuts' way left out): the retract and the approach with head.tip_zone_mm left out (the nozzle is at the surface there), the travel between the retract points with the whole head; a route the head does not clear is not taken; where the head clears no route, the run is refused, or with accept_head_collisions the route the nozzle line clears is taken with a warning (head_too_close counts them; head_min_distance_mm leaves them out, and is absent where no traverse cleared the head)".into()),
            surfaces_in_the_cuts_way: Some(unchecked),
            surfaces_note: Some("surfaces that lie on the tool axis line where a cut ends or starts (its contour end and exit, its pierce and contour start, up to the retract plus the nozzle) are not checked for the traverse there: the head meets them while it cuts or pierces, whatever the traverse does; a surface the cut's curve does not name (another workpiece in the same place, or in the way of the cut), or one it names that comes back over the head line from 3/4 of the clearance up (listed in own_surface_over_the_head)".into()),
            own_surface_over_the_head: Some(own),
            unchecked_note: Some("where no route keeps the clearance (unchecked, with the reason and the surfaces the routes were checked without), the program falls back to the unchecked retract along the tool axis, straight move and approach, with a warning; a reason that starts 'proven' shows that no route can exist (the retract or approach line itself is blocked)".into()),
            searched_note: Some("searched: the gaps where no route shape (straight, lifted, over the safe plane) cleared and a search around the part found a path, the head turned to one tool axis for the travel; lifted counts every route that is not straight".into()),
            note: None,
        }
    }
}
