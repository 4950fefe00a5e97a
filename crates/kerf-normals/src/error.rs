//! The error type of the normals stage.

use kerf_nurbs::Readable;
use thiserror::Error;

/// What can go wrong when giving cutting points their normals.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum NormalsError {
    /// A cutting point is farther from its surface than `on_surface_tolerance_mm`: the curve does
    /// not lie on the surface it names. Fix: check that the curve's `surface` id is right, or
    /// raise the tolerance if the CAD export is coarse.
    #[error("point at t = {} is {distance:.3e} mm from its surface (on_surface_tolerance_mm {} mm): the curve does not lie on the surface", Readable(*.t), Readable(*.tolerance))]
    OffSurface {
        /// Curve parameter.
        t: f64,
        /// Distance from the surface.
        distance: f64,
        /// The allowed distance.
        tolerance: f64,
    },
    /// The surface has no defined normal at the point (a degenerate patch or a zero-area
    /// region). Fix: repair the surface.
    #[error("surface has no normal at the point for t = {}", Readable(*.t))]
    NoNormal {
        /// Curve parameter.
        t: f64,
    },
    /// The normal reverses between neighbouring points: the surface's orientation is
    /// inconsistent there (a flipped patch or triangle). Fix: orient the surface consistently
    /// (or set `flip` on the part that is reversed).
    #[error("normal reverses at t = {} ({angle:.1} degrees between neighbouring points): inconsistent surface orientation", Readable(*.t))]
    Reversed {
        /// Curve parameter where the reversal was found.
        t: f64,
        /// The angle between the two normals, degrees.
        angle: f64,
    },
    /// An option is out of range.
    #[error("option {name}: {reason} (got {})", Readable(*.value))]
    BadOption {
        /// Its name.
        name: &'static str,
        /// Its value.
        value: f64,
        /// What is wrong.
        reason: &'static str,
    },
    /// The mesh cannot be used: no triangles left after removing degenerate ones, or
    /// non-finite vertices. Fix: export the mesh again.
    #[error("mesh: {0}")]
    BadMesh(String),
    /// Re-discretizing a stretch after inserting points failed.
    #[error(transparent)]
    Discretize(#[from] kerf_discretize::DiscretizeError),
    /// Inserting points against the normal step would exceed the limit. Fix: raise
    /// `max_normal_step_deg`.
    #[error("more than {limit} points inserted for the normal step; raise the options' max_normal_step_deg")]
    TooManyInserted {
        /// The limit.
        limit: usize,
    },
}

/// `Result` with [`NormalsError`].
pub type Result<T> = std::result::Result<T, NormalsError>;
