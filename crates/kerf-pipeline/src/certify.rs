//! A toolpath certified again against its curves: how cutting points kerf did not make in this
//! run (read back from a `kerf.toolpath/1` file, from kerf or any other tool) earn a proven
//! chord term in a program's tolerance budget (`kerf gcode --curves`). Without it the file's
//! `tolerance` is only a claim, and the program says so.

use std::path::Path;

use kerf_discretize::Discretization;
use kerf_format::toolpath::ToolpathFile;
use kerf_format::CurvesFile;

use crate::error::{Error, Result};

/// A toolpath whose every segment kerf proved within the file's tolerance of its curve.
///
/// Made only by [`CertifiedToolpath::new`], so holding one is the proof: for each path, the
/// curve of the same id and index certifies the params ([`Discretization::certify`], the
/// discretizer's own bound), and the written points' distance from the curve's points at their
/// params is added to the bound (a chord whose ends move by at most `d` stays within `d` of the
/// old chord).
#[derive(Debug, Clone)]
pub struct CertifiedToolpath {
    toolpath: ToolpathFile,
    bound_mm: f64,
}

impl CertifiedToolpath {
    /// Certifies `toolpath` against `curves` (`source` names the toolpath file in errors).
    ///
    /// # Errors
    /// [`Error::NotCertified`] naming the path: a missing or differently named curve (the
    /// format's rule: one path per curve, same id, same order), params the certificate refuses
    /// (not from one end of the domain to the other, a C0 break missed, a segment whose bound
    /// exceeds the tolerance), or points off their curve by enough to take a segment over it.
    pub fn new(toolpath: ToolpathFile, curves: &CurvesFile, source: Option<&Path>) -> Result<Self> {
        let file = source.map(Path::to_path_buf);
        let tolerance = toolpath.tolerance;
        let mut bound_mm: f64 = 0.0;
        for (index, path) in toolpath.paths.iter().enumerate() {
            let refuse = |reason: String, source: Option<Box<kerf_discretize::DiscretizeError>>| {
                Error::NotCertified {
                    file: file.clone(),
                    index,
                    id: path.id.clone(),
                    reason,
                    source,
                }
            };
            let curve = match curves.curves.get(index) {
                Some(c) if c.id == path.id => &c.curve,
                Some(c) => {
                    return Err(refuse(
                        format!("the curves file has {:?} at this index", c.id),
                        None,
                    ))
                }
                None => {
                    return Err(refuse(
                        format!("the curves file has only {} curves", curves.curves.len()),
                        None,
                    ))
                }
            };
            if path.params.len() != path.points.len() {
                return Err(refuse(
                    format!(
                        "{} params for {} points",
                        path.params.len(),
                        path.points.len()
                    ),
                    None,
                ));
            }
            let d = Discretization::certify(curve, &path.params, tolerance).map_err(|e| {
                refuse(
                    "the certificate refuses its params".into(),
                    Some(Box::new(e)),
                )
            })?;
            let off = d
                .points()
                .iter()
                .enumerate()
                .map(|(n, p)| (path.points.position(n) - p).norm())
                .fold(0.0, f64::max);
            // The norm rounds by a few eps of itself.
            let bound = d.max_chord_error() + off * (1.0 + 4.0 * f64::EPSILON);
            if bound.is_nan() || bound > tolerance {
                return Err(refuse(
                    format!(
                        "points lie up to {off:.3e} mm from the curve at their params, so a chord may be {bound:.6e} mm from it, over the tolerance {tolerance} mm"
                    ),
                    None,
                ));
            }
            bound_mm = bound_mm.max(bound);
        }
        if curves.curves.len() != toolpath.paths.len() {
            return Err(Error::NotCertified {
                file,
                index: toolpath.paths.len(),
                id: String::new(),
                reason: format!(
                    "{} paths for {} curves (one path per curve)",
                    toolpath.paths.len(),
                    curves.curves.len()
                ),
                source: None,
            });
        }
        Ok(Self { toolpath, bound_mm })
    }

    /// The toolpath.
    pub fn toolpath(&self) -> &ToolpathFile {
        &self.toolpath
    }

    /// The largest certified chord error of any segment, mm (`<=` the file's tolerance).
    pub fn bound_mm(&self) -> f64 {
        self.bound_mm
    }
}
