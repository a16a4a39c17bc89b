//! Ray directions. The kernel always shoots its ray along `+z` of a *ray frame*; another
//! direction is obtained by a proper rotation that permutes and negates axes (determinant +1,
//! so orientations and winding numbers are unchanged). The perturbation `(ε1, ε2, ε3)` follows the
//! frame's axes, which is what makes the direction-independence test a real oracle: a different
//! frame resolves every degeneracy differently, yet must give the same `w` off the surface.

/// The axis-aligned direction of the ray.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum RayAxis {
    /// `+z` (frame = world; ε1 on x, ε2 on y, ε3 on z). Default.
    #[default]
    PosZ,
    /// `−z`: frame `(x, −y, −z)`.
    NegZ,
    /// `+x`: frame `(y, z, x)`.
    PosX,
    /// `−x`: frame `(y, −z, −x)`.
    NegX,
    /// `+y`: frame `(z, x, y)`.
    PosY,
    /// `−y`: frame `(z, −x, −y)`.
    NegY,
}

impl RayAxis {
    /// All six directions.
    pub const ALL: [RayAxis; 6] = [
        RayAxis::PosZ,
        RayAxis::NegZ,
        RayAxis::PosX,
        RayAxis::NegX,
        RayAxis::PosY,
        RayAxis::NegY,
    ];

    /// For each frame axis: which world axis it reads and with which sign.
    #[inline]
    pub fn map(self) -> [(usize, bool); 3] {
        match self {
            RayAxis::PosZ => [(0, false), (1, false), (2, false)],
            RayAxis::NegZ => [(0, false), (1, true), (2, true)],
            RayAxis::PosX => [(1, false), (2, false), (0, false)],
            RayAxis::NegX => [(1, false), (2, true), (0, true)],
            RayAxis::PosY => [(2, false), (0, false), (1, false)],
            RayAxis::NegY => [(2, false), (0, true), (1, true)],
        }
    }

    /// World → frame for a value type with negation.
    #[inline]
    pub fn to_frame<T: Copy + std::ops::Neg<Output = T>>(self, v: [T; 3]) -> [T; 3] {
        // Written out (not `array::map`): the closure version was an out-of-line call on the
        // per-query path, and reading its result back stalled on store forwarding.
        let [m0, m1, m2] = self.map();
        let one = |(axis, neg): (usize, bool)| if neg { -v[axis] } else { v[axis] };
        [one(m0), one(m1), one(m2)]
    }

    /// Frame → world (the inverse rotation).
    #[inline]
    pub fn to_world<T: Copy + std::ops::Neg<Output = T> + Default>(self, v: [T; 3]) -> [T; 3] {
        let mut w = [T::default(); 3];
        for (k, (axis, neg)) in self.map().into_iter().enumerate() {
            w[axis] = if neg { -v[k] } else { v[k] };
        }
        w
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_are_proper_rotations() {
        for r in RayAxis::ALL {
            let m: Vec<[f64; 3]> = (0..3)
                .map(|i| {
                    let mut e = [0.0; 3];
                    e[i] = 1.0;
                    r.to_frame(e)
                })
                .collect();
            // columns m[i] = image of e_i; determinant +1
            let det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
                - m[1][0] * (m[0][1] * m[2][2] - m[0][2] * m[2][1])
                + m[2][0] * (m[0][1] * m[1][2] - m[0][2] * m[1][1]);
            assert_eq!(det, 1.0, "{r:?}");
            let v = [1.5, -2.0, 3.25];
            assert_eq!(r.to_world(r.to_frame(v)), v);
        }
        // The ray +z of the frame points along the named world direction.
        assert_eq!(RayAxis::NegX.to_world([0.0, 0.0, 1.0]), [-1.0, 0.0, 0.0]);
        assert_eq!(RayAxis::PosY.to_world([0.0, 0.0, 1.0]), [0.0, 1.0, 0.0]);
        assert_eq!(RayAxis::NegZ.to_world([0.0, 0.0, 1.0]), [0.0, 0.0, -1.0]);
    }
}
