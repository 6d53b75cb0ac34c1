//! The whole arm as distance-query pieces: each section's arc AND the rigid part after
//! it (the end plate of an inner section, the gripper after the last one).
//!
//! The arcs alone (planning paper eq. 11–18) leave out the rigid offsets `b_i` along each
//! arc's tip axis (redundancy paper eq. 3): on the blackberry arm 4 cm of plates and an
//! 8 cm gripper that can touch a cane while every arc is clear. Each offset is a straight
//! segment along the tip's z axis, which is exactly an arc of zero curvature, so the same
//! exact queries of [`super::obstacle`] serve it.

use super::arc_point::PlacedArc;
use super::obstacle::{closest_to_arcs, closest_to_arcs_within, Closest, Obstacle};
use crate::arc::ArcParams;
use crate::chain::{check_q, SectionModel};
use crate::error::Result;
use crate::kinematics::Kinematics;
use crate::math::Frame;

/// One piece of the arm's body.
#[derive(Debug, Clone, Copy)]
pub struct Piece {
    /// The piece as a placed arc (a straight one for a rigid part).
    pub arc: PlacedArc,
    /// The section it belongs to (the rigid part follows that section's arc).
    pub section: usize,
    /// True for the rigid plate or gripper after the arc.
    pub rigid: bool,
}

/// The closest pair between the arm's body (arcs and rigid parts) and an obstacle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyClosest {
    /// The pair; `section` and `s` locate the arm point on `rigid`'s piece: a fraction of
    /// the arc, or of the rigid offset after it.
    pub closest: Closest,
    /// Whether the arm point lies on a rigid part (plate or gripper).
    pub rigid: bool,
}

/// Writes every piece of the arm at `q` (already checked) into `out`: for each section
/// its arc, then its rigid offset when that is longer than zero.
pub fn placed_pieces_into<K: SectionModel + ?Sized>(model: &K, q: &[f64], out: &mut Vec<Piece>) {
    out.clear();
    let mut f = Frame::identity();
    for i in 0..model.n_sections() {
        let st = model.section_state(i, &q[3 * i..3 * i + 3]);
        out.push(Piece {
            arc: PlacedArc::new(f, st.arc),
            section: i,
            rigid: false,
        });
        let tip = f.compose(&st.arc.frame(1.0));
        if st.offset > 0.0 {
            let straight = ArcParams {
                length: st.offset,
                ux: 0.0,
                uy: 0.0,
            };
            out.push(Piece {
                arc: PlacedArc::new(tip, straight),
                section: i,
                rigid: true,
            });
        }
        // The next section's base: the offset along the tip's z, then the twist about it.
        let (c, s) = st.twist;
        let (r0, r1, r2) = (tip.rot.column(0), tip.rot.column(1), tip.rot.column(2));
        f = Frame {
            rot: crate::math::Mat3::from_columns(&[
                r0 * c + r1 * s,
                r1 * c - r0 * s,
                r2.into_owned(),
            ]),
            pos: tip.pos + r2 * st.offset,
        };
    }
}

/// The closest pair over `pieces` to `obstacle`, when closer than `cutoff` (exact; far
/// pieces are skipped by bounding spheres). `None` when every piece is at least `cutoff`
/// away.
pub fn closest_piece_within(
    pieces: &[Piece],
    obstacle: &Obstacle,
    cutoff: f64,
) -> Option<BodyClosest> {
    let mut best: Option<BodyClosest> = None;
    let mut limit = cutoff;
    let spheres = match obstacle {
        Obstacle::Curve(c) => Some(c.interval_spheres()),
        Obstacle::Segment(s) => Some(s.as_curve().interval_spheres()),
        _ => None,
    };
    for p in pieces {
        if let Some(spheres) = spheres {
            // Cull by the curve's per-interval bounding spheres (the whole-curve sphere of
            // a long cane holds most of the arm): a piece lies within half its length of
            // its middle point.
            let middle = p.arc.point(0.5);
            let half = 0.5 * p.arc.arc.params.length;
            // Squared, to spare a square root per interval: |m − c| ≥ r + L/2 + limit.
            if spheres.iter().all(|(c, r)| {
                let reach = r + half + limit;
                (middle - c).norm_squared() >= reach * reach
            }) {
                continue;
            }
        }
        if let Some(c) = closest_to_arcs_within(std::slice::from_ref(&p.arc), obstacle, limit) {
            if c.distance < limit {
                limit = c.distance;
                best = Some(BodyClosest {
                    closest: Closest {
                        section: p.section,
                        ..c
                    },
                    rigid: p.rigid,
                });
            }
        }
    }
    best
}

/// The closest pair between the whole body of `model` at `q` (arcs, plates, gripper) and
/// `obstacle`. Never farther than [`super::closest`], which sees the arcs only.
///
/// # Errors
/// [`crate::Error::Shape`] / [`crate::Error::NonFinite`] for a bad `q`;
/// [`crate::Error::Parameter`] for a model without sections.
pub fn closest_body<K: Kinematics + ?Sized>(
    model: &K,
    q: &[f64],
    obstacle: &Obstacle,
) -> Result<BodyClosest> {
    check_q(model, q)?;
    let mut pieces = Vec::with_capacity(2 * model.n_sections());
    placed_pieces_into(model, q, &mut pieces);
    let mut best: Option<BodyClosest> = None;
    for p in &pieces {
        let c = closest_to_arcs(std::slice::from_ref(&p.arc), obstacle);
        if best.is_none_or(|b| c.distance < b.closest.distance) {
            best = Some(BodyClosest {
                closest: Closest {
                    section: p.section,
                    ..c
                },
                rigid: p.rigid,
            });
        }
    }
    // Every model has at least one section (its constructors refuse none); an empty one
    // is still an error here rather than a panic.
    best.ok_or_else(|| crate::Error::parameter("model", 0.0, "has no sections"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::distance::{closest, Segment};
    use crate::math::Vec3;
    use crate::SoftArm;

    #[test]
    fn the_gripper_is_seen_where_the_arcs_are_not() {
        let arm = SoftArm::blackberry();
        let q = [0.0166; 9];
        let tip = arm.forward(&q).unwrap();
        let p = Vec3::new(tip[(0, 3)], tip[(1, 3)], tip[(2, 3)]);
        // A segment crossing the gripper's axis 1 cm behind the end-effector origin.
        let z = Vec3::new(tip[(0, 2)], tip[(1, 2)], tip[(2, 2)]);
        let x = Vec3::new(tip[(0, 0)], tip[(1, 0)], tip[(2, 0)]);
        let c = p - z * 0.01;
        let seg = Obstacle::Segment(Segment::new(c - x * 0.1, c + x * 0.1).unwrap());
        let body = closest_body(&arm, &q, &seg).unwrap();
        assert!(body.rigid && body.closest.section == 2);
        assert!(body.closest.distance < 1e-9, "{}", body.closest.distance);
        let arcs = closest(&arm, &q, &seg).unwrap();
        assert!(arcs.distance > 0.04, "{}", arcs.distance);
    }

    #[test]
    fn pieces_end_at_the_end_effector() {
        let arm = SoftArm::blackberry();
        let q = [0.01, 0.02, 0.005, 0.015, 0.0, 0.02, 0.01, 0.01, 0.03];
        let mut pieces = Vec::new();
        placed_pieces_into(&arm, &q, &mut pieces);
        assert_eq!(pieces.len(), 6);
        let end = pieces.last().unwrap().arc.point(1.0);
        let tip = arm.forward(&q).unwrap();
        let want = Vec3::new(tip[(0, 3)], tip[(1, 3)], tip[(2, 3)]);
        assert!((end - want).norm() < 1e-12);
        // Each rigid piece starts where its arc ends.
        for w in pieces.chunks(2) {
            assert!((w[0].arc.point(1.0) - w[1].arc.point(0.0)).norm() < 1e-12);
        }
    }
}
