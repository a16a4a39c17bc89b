//! Oriented point clouds: positions, unit normals and optional per-point areas, validated once.
//! Evaluated by `eval::fast::PointCloudWindingNumber`.

use std::fmt;

/// A point cloud that cannot be used as given.
#[derive(Clone, Debug, PartialEq)]
pub enum PointCloudError {
    /// `normals` (or `areas`) do not have one entry per point.
    LengthMismatch {
        /// What has the wrong length: `"normals"` or `"areas"`.
        what: &'static str,
        /// Number of points.
        points: usize,
        /// Number of entries found.
        found: usize,
    },
    /// A coordinate, normal component or area is NaN or infinite, or an area is negative.
    InvalidValue {
        /// What: `"position"`, `"normal"` or `"area"`.
        what: &'static str,
        /// Point index (0-based).
        index: usize,
    },
}

impl fmt::Display for PointCloudError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PointCloudError::LengthMismatch {
                what,
                points,
                found,
            } => write!(f, "{points} points but {found} {what}"),
            PointCloudError::InvalidValue { what, index } => {
                write!(
                    f,
                    "point {index} has an invalid {what} (NaN, infinite or negative)"
                )
            }
        }
    }
}

impl std::error::Error for PointCloudError {}

/// An oriented point cloud: positions, normals (normalised on construction; a zero normal makes
/// the point inert) and optional per-point areas `aᵢ`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PointCloud {
    positions: Vec<[f64; 3]>,
    normals: Vec<[f64; 3]>,
    areas: Option<Vec<f64>>,
}

impl PointCloud {
    /// Validates and stores the cloud. Normals are normalised (their length is ignored: the
    /// strength of a point is its area).
    pub fn new(
        positions: Vec<[f64; 3]>,
        normals: Vec<[f64; 3]>,
        areas: Option<Vec<f64>>,
    ) -> Result<Self, PointCloudError> {
        let n = positions.len();
        if normals.len() != n {
            return Err(PointCloudError::LengthMismatch {
                what: "normals",
                points: n,
                found: normals.len(),
            });
        }
        if let Some(a) = &areas {
            if a.len() != n {
                return Err(PointCloudError::LengthMismatch {
                    what: "areas",
                    points: n,
                    found: a.len(),
                });
            }
            if let Some(index) = a.iter().position(|v| !v.is_finite() || *v < 0.0) {
                return Err(PointCloudError::InvalidValue {
                    what: "area",
                    index,
                });
            }
        }
        if let Some(index) = positions
            .iter()
            .position(|p| p.iter().any(|v| !v.is_finite()))
        {
            return Err(PointCloudError::InvalidValue {
                what: "position",
                index,
            });
        }
        let mut unit = normals;
        for (index, nrm) in unit.iter_mut().enumerate() {
            let l2 = nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2];
            if !l2.is_finite() {
                return Err(PointCloudError::InvalidValue {
                    what: "normal",
                    index,
                });
            }
            if l2 > 0.0 {
                let l = l2.sqrt();
                *nrm = nrm.map(|v| v / l);
            }
        }
        Ok(PointCloud {
            positions,
            normals: unit,
            areas,
        })
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.positions.len()
    }

    /// True when the cloud has no points.
    pub fn is_empty(&self) -> bool {
        self.positions.is_empty()
    }

    /// Positions.
    pub fn positions(&self) -> &[[f64; 3]] {
        &self.positions
    }

    /// Unit normals (zero for a point given a zero normal).
    pub fn normals(&self) -> &[[f64; 3]] {
        &self.normals
    }

    /// Per-point areas, when given.
    pub fn areas(&self) -> Option<&[f64]> {
        self.areas.as_deref()
    }
}
