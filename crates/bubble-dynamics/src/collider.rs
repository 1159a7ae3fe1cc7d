//! Static obstacles: planes (ground, walls), solid spheres and solid boxes.

use glam::DVec3;

use crate::error::ParamError;
use crate::validate::{finite_vec, non_negative, nonzero_vec, positive, unit_interval};

/// Default restitution of a static collider (a film on a dry surface keeps little bounce).
pub const DEFAULT_RESTITUTION: f64 = 0.3;
/// Default Coulomb friction coefficient of a static collider.
pub const DEFAULT_FRICTION: f64 = 0.4;

/// A static obstacle. Bubbles stay outside it; contacts bounce with `restitution` (the
/// ratio of the bubble's centre-of-mass normal speeds after and before) and slide with
/// Coulomb `friction`.
#[derive(Clone, Debug, PartialEq)]
pub enum Collider {
    /// Half-space: the solid lies on the side opposite to `normal`.
    Plane {
        /// A point on the plane, m.
        point_m: DVec3,
        /// Normal pointing out of the solid (need not be unit length).
        normal: DVec3,
        /// Restitution in [0, 1].
        restitution: f64,
        /// Coulomb friction coefficient.
        friction: f64,
    },
    /// Solid sphere.
    Sphere {
        /// Centre, m.
        center_m: DVec3,
        /// Radius, m.
        radius_m: f64,
        /// Restitution in [0, 1].
        restitution: f64,
        /// Coulomb friction coefficient.
        friction: f64,
    },
    /// Solid axis-aligned box.
    Box {
        /// Lower corner, m.
        min_m: DVec3,
        /// Upper corner, m.
        max_m: DVec3,
        /// Restitution in [0, 1].
        restitution: f64,
        /// Coulomb friction coefficient.
        friction: f64,
    },
}

impl Collider {
    /// The ground: the plane y = `height_m` with the solid below, default contact.
    pub fn ground(height_m: f64) -> Self {
        Self::plane(DVec3::new(0.0, height_m, 0.0), DVec3::Y)
    }

    /// A plane through `point_m` with outward `normal`, default contact.
    pub fn plane(point_m: DVec3, normal: DVec3) -> Self {
        Self::Plane {
            point_m,
            normal,
            restitution: DEFAULT_RESTITUTION,
            friction: DEFAULT_FRICTION,
        }
    }

    /// A solid sphere, default contact.
    pub fn sphere(center_m: DVec3, radius_m: f64) -> Self {
        Self::Sphere {
            center_m,
            radius_m,
            restitution: DEFAULT_RESTITUTION,
            friction: DEFAULT_FRICTION,
        }
    }

    /// A solid axis-aligned box, default contact.
    pub fn cuboid(min_m: DVec3, max_m: DVec3) -> Self {
        Self::Box {
            min_m,
            max_m,
            restitution: DEFAULT_RESTITUTION,
            friction: DEFAULT_FRICTION,
        }
    }

    /// Restitution and friction of this collider.
    pub fn contact(&self) -> (f64, f64) {
        match *self {
            Self::Plane {
                restitution,
                friction,
                ..
            }
            | Self::Sphere {
                restitution,
                friction,
                ..
            }
            | Self::Box {
                restitution,
                friction,
                ..
            } => (restitution, friction),
        }
    }

    /// Signed distance from `p` to the surface in m (negative inside the solid) and the
    /// outward unit normal of the nearest surface point.
    pub fn signed_distance_m(&self, p: DVec3) -> (f64, DVec3) {
        match *self {
            Self::Plane {
                point_m, normal, ..
            } => {
                let n = normal.normalize();
                ((p - point_m).dot(n), n)
            }
            Self::Sphere {
                center_m, radius_m, ..
            } => {
                let d = p - center_m;
                let n = d.try_normalize().unwrap_or(DVec3::Y);
                (d.length() - radius_m, n)
            }
            Self::Box { min_m, max_m, .. } => box_distance(p, min_m, max_m),
        }
    }

    pub(crate) fn validate(&self) -> Result<(), ParamError> {
        let (restitution, friction) = self.contact();
        unit_interval("restitution", restitution)?;
        non_negative("friction", friction)?;
        match *self {
            Self::Plane {
                point_m, normal, ..
            } => {
                finite_vec("point_m", point_m)?;
                nonzero_vec("normal", normal)
            }
            Self::Sphere {
                center_m, radius_m, ..
            } => {
                finite_vec("center_m", center_m)?;
                positive("radius_m", radius_m)
            }
            Self::Box { min_m, max_m, .. } => {
                finite_vec("min_m", min_m)?;
                finite_vec("max_m", max_m)?;
                if min_m.cmplt(max_m).all() {
                    Ok(())
                } else {
                    Err(ParamError::new(
                        "max_m",
                        max_m.to_array(),
                        format!("must exceed min_m = {:?} on every axis", min_m.to_array()),
                    ))
                }
            }
        }
    }
}

fn box_distance(p: DVec3, min_m: DVec3, max_m: DVec3) -> (f64, DVec3) {
    let center = 0.5 * (min_m + max_m);
    let half = 0.5 * (max_m - min_m);
    let local = p - center;
    let q = local.abs() - half;
    let outside = q.max(DVec3::ZERO);
    if outside.length_squared() > 0.0 {
        let n = (outside * local.signum()).normalize();
        return (outside.length(), n);
    }
    // Inside: leave through the nearest face.
    let axis = if q.x >= q.y && q.x >= q.z {
        0
    } else if q.y >= q.z {
        1
    } else {
        2
    };
    let n = DVec3::AXES[axis] * local[axis].signum();
    (q[axis], n)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_distance_is_negative_inside_and_euclidean_outside() {
        let b = Collider::cuboid(DVec3::ZERO, DVec3::new(2.0, 1.0, 1.0));
        let (d, n) = b.signed_distance_m(DVec3::new(1.0, 0.9, 0.5));
        assert!(
            (d + 0.1).abs() < 1e-12 && n == DVec3::Y,
            "inside: d = {d}, n = {n:?}"
        );
        let (d, n) = b.signed_distance_m(DVec3::new(3.0, 2.0, 0.5));
        assert!((d - 2f64.sqrt()).abs() < 1e-12, "corner distance {d}");
        assert!(
            (n - DVec3::new(1.0, 1.0, 0.0).normalize()).length() < 1e-12,
            "corner normal {n:?}"
        );
    }

    #[test]
    fn sphere_and_plane_distances() {
        let s = Collider::sphere(DVec3::X, 0.5);
        assert!((s.signed_distance_m(DVec3::new(1.0, 2.0, 0.0)).0 - 1.5).abs() < 1e-12);
        let p = Collider::plane(DVec3::ZERO, DVec3::new(0.0, 3.0, 0.0));
        assert!((p.signed_distance_m(DVec3::new(5.0, -0.25, 1.0)).0 + 0.25).abs() < 1e-12);
    }
}
