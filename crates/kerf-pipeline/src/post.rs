//! The kinematics stage on a toolpath document: the machine axes of every path (`kerf post`
//! as one library call), with the placement of the part.

use std::path::Path;

use kerf_format::toolpath::{ToolpathFile, ToolpathPoints};
use kerf_kinematics::{solve_paths, AxesFile, Machine, PathInput, PathOptions, Pose, SolvedPath};
use nalgebra::Vector3;

use crate::error::{kin, Error, Result};
use crate::place::{place, PlaceMode, Placed, AUTO_CLEARANCE_MM};

/// What a toolpath path without normals gets from [`toolpath_poses`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum MissingNormals {
    /// The tool axis +z at every point (flat cutting with a vertical beam; what the motion
    /// stage does with a `kerf.toolpath/1` of positions).
    Vertical,
    /// [`Error::NoNormals`] naming the path (what `kerf post` does: a 5-axis program needs
    /// the surface normals).
    Error,
}

/// The poses `[x, y, z, i, j, k]` of every path of `toolpath`; `source` names the file in
/// errors.
///
/// # Errors
/// [`Error::NoNormals`] for a path of positions only with [`MissingNormals::Error`].
pub fn toolpath_poses(
    toolpath: &ToolpathFile,
    missing: MissingNormals,
    source: Option<&Path>,
) -> Result<Vec<Vec<Pose>>> {
    let mut poses = Vec::with_capacity(toolpath.paths.len());
    for (index, p) in toolpath.paths.iter().enumerate() {
        if matches!(p.points, ToolpathPoints::Positions(_)) && missing == MissingNormals::Error {
            return Err(Error::NoNormals {
                file: source.map(Path::to_path_buf),
                index,
                id: p.id.clone(),
            });
        }
        poses.push(
            (0..p.points.len())
                .map(|n| {
                    let q = p.points.position(n);
                    let a = p.points.normal(n).unwrap_or_else(Vector3::z);
                    Pose::new(q.x, q.y, q.z, a.x, a.y, a.z)
                })
                .collect(),
        );
    }
    Ok(poses)
}

/// The machine axes of a toolpath: what [`post_toolpath`] returns.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct Posted {
    /// The solved paths, one per toolpath path, in its order.
    pub solved: Vec<SolvedPath>,
    /// Their `kerf.axes/1` document.
    pub axes: AxesFile,
    /// Where the part was placed on the machine.
    pub placed: Placed,
}

/// Places the part (`mode`; [`PlaceMode::Auto`] keeps [`AUTO_CLEARANCE_MM`] from every linear
/// limit) and solves every path of `toolpath` on `machine` with `options`, the paths in
/// parallel. `missing` says what a path without normals gets; `source` names the toolpath
/// file in errors.
///
/// # Errors
/// [`Error::NoNormals`]; [`Error::Kinematics`] for options out of range, a placement that
/// does not fit or a path that cannot be solved (naming the path, point and axis).
pub fn post_toolpath(
    machine: &Machine,
    toolpath: &ToolpathFile,
    options: &PathOptions,
    mode: PlaceMode,
    missing: MissingNormals,
    source: Option<&Path>,
) -> Result<Posted> {
    let poses = toolpath_poses(toolpath, missing, source)?;
    let ids: Vec<&str> = toolpath.paths.iter().map(|p| p.id.as_str()).collect();
    let placed = place(
        machine,
        &ids,
        &poses,
        mode,
        // A toolpath names no sheet thickness: its paths may be turned where only the other
        // side is reachable, as a thin sheet's (the default).
        &kerf_kinematics::AutoPlaceOptions::default()
            .with_path_options(*options)
            .with_margin_mm(AUTO_CLEARANCE_MM),
        source,
    )?;
    let poses = placed.apply(&poses);
    let inputs: Vec<PathInput<'_>> = ids
        .iter()
        .zip(&poses)
        .map(|(id, q)| PathInput {
            id,
            poses: q,
            curve: None,
        })
        .collect();
    let solved = solve_paths(machine, &inputs, options).map_err(kin(source))?;
    let axes = AxesFile::new(machine, &solved);
    Ok(Posted {
        solved,
        axes,
        placed,
    })
}
