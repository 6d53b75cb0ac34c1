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
use crate::math::{Frame, Vec3};

/// One piece of the arm's body.
#[derive(Debug, Clone, Copy)]
pub struct Piece {
    /// The piece as a placed arc (a straight one for a rigid part).
    pub arc: PlacedArc,
    /// The section it belongs to (the rigid part follows that section's arc).
    pub section: usize,
    /// True for the rigid plate or gripper after the arc.
    pub rigid: bool,
    /// The surface's radius about the piece's backbone (m): 0 for the bare backbone of
    /// [`placed_pieces_into`], the body's radius in [`crate::body::Body::pieces_into`].
    pub radius: f64,
    /// The midpoint of the piece's chord: with [`Piece::half`], a ball holding it.
    pub centre: Vec3,
    /// Half the piece's length L. Every point x of a curve of length L from A to B has
    /// |x − A| + |x − B| ≤ L, hence |x − (A + B)/2| ≤ L/2: the ball needs no
    /// trigonometry beyond the arc's tip, which the queries need anyway.
    pub half: f64,
}

impl Piece {
    /// The bare piece `arc` of `section` (radius 0), with its bounding ball.
    pub(crate) fn new(arc: PlacedArc, section: usize, rigid: bool) -> Self {
        Piece {
            centre: arc.frame.pos + arc.frame.rot * (0.5 * arc.arc.tip()),
            half: 0.5 * arc.arc.params.length,
            arc,
            section,
            rigid,
            radius: 0.0,
        }
    }
}

/// An axis-aligned box holding the whole body: the union of every piece's bounding ball,
/// grown by the piece's radius (so that it holds the surfaces).
/// Built once per configuration, it lets a far obstacle be dismissed with a handful of
/// sphere tests instead of one per piece and sphere.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyBox {
    lo: Vec3,
    hi: Vec3,
}

impl BodyBox {
    /// The box around the bounding balls of `pieces`, each grown by its radius (empty,
    /// i.e. clear of everything, when there are none).
    pub fn around(pieces: &[Piece]) -> Self {
        let inf = Vec3::repeat(f64::INFINITY);
        pieces.iter().fold(BodyBox { lo: inf, hi: -inf }, |b, p| {
            let r = Vec3::repeat(p.half + p.radius);
            BodyBox {
                lo: b.lo.inf(&(p.centre - r)),
                hi: b.hi.sup(&(p.centre + r)),
            }
        })
    }

    /// Squared distance between this box and the box (`lo`, `hi`): the per-axis gaps
    /// (0 where the boxes overlap along the axis), squared and summed.
    #[inline]
    fn distance_squared(&self, lo: &Vec3, hi: &Vec3) -> f64 {
        (0..3)
            .map(|i| {
                let gap = (lo[i] - self.hi[i]).max(self.lo[i] - hi[i]).max(0.0);
                gap * gap
            })
            .sum()
    }

    /// True when the ball (`centre`, `radius`) lies at least `limit` from every point of
    /// the box, hence of the body: `|c − box| ≥ radius + limit` (squared, no square root).
    #[inline]
    pub fn clear_of(&self, centre: &Vec3, radius: f64, limit: f64) -> bool {
        let reach = radius + limit;
        self.distance_squared(centre, centre) >= reach * reach
    }

    /// True when the box (`lo`, `hi`) lies at least `limit` from every point of this box.
    #[inline]
    pub fn clear_of_box(&self, lo: &Vec3, hi: &Vec3, limit: f64) -> bool {
        self.distance_squared(lo, hi) >= limit * limit
    }
}

/// The closest pair between the arm's body (arcs and rigid parts) and an obstacle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyClosest {
    /// The backbone pair; `section` and `s` locate the arm point on `rigid`'s piece: a
    /// fraction of the arc, or of the rigid part after it.
    pub closest: Closest,
    /// Whether the arm point lies on a rigid part (plate or gripper).
    pub rigid: bool,
    /// The piece's surface distance: `closest.distance` less the piece's radius (m).
    pub surface: f64,
    /// The piece's index in the slice it was found in.
    pub piece: usize,
}

/// Writes every piece of the arm at `q` (already checked) into `out`: for each section
/// its arc, then its rigid offset when that is longer than zero.
pub fn placed_pieces_into<K: SectionModel + ?Sized>(model: &K, q: &[f64], out: &mut Vec<Piece>) {
    out.clear();
    let mut f = Frame::identity();
    for i in 0..model.n_sections() {
        let st = model.section_state(i, &q[3 * i..3 * i + 3]);
        out.push(Piece::new(PlacedArc::new(f, st.arc), i, false));
        let tip = f.compose(&st.arc.frame(1.0));
        if st.offset > 0.0 {
            let straight = ArcParams {
                length: st.offset,
                ux: 0.0,
                uy: 0.0,
            };
            out.push(Piece::new(PlacedArc::new(tip, straight), i, true));
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

/// The piece of `pieces` (held by `bound`, [`BodyBox::around`] them) whose SURFACE is
/// nearest `obstacle` (the backbone distance less the piece's radius), when nearer than
/// `cutoff`: exact, far pieces skipped by bounding spheres. With bare pieces (radius 0)
/// it is the nearest backbone. `None` when every surface is at least `cutoff` away.
pub fn closest_piece_within(
    pieces: &[Piece],
    bound: &BodyBox,
    obstacle: &Obstacle,
    cutoff: f64,
) -> Option<BodyClosest> {
    let mut best: Option<BodyClosest> = None;
    scan(pieces, bound, obstacle, cutoff, 0.0, |hit| best = Some(hit));
    best
}

/// Appends to `out` the closest pair of every piece of `pieces` (held by `bound`) whose
/// surface is nearer `obstacle` than `cutoff` and than the nearest surface plus `slack`
/// (m), in the pieces' order. Every piece that qualifies is appended; a few appended
/// early may lie beyond the nearest plus `slack` (the nearest is only known at the end).
pub fn pieces_within(
    pieces: &[Piece],
    bound: &BodyBox,
    obstacle: &Obstacle,
    (cutoff, slack): (f64, f64),
    out: &mut Vec<BodyClosest>,
) {
    scan(pieces, bound, obstacle, cutoff, slack, |hit| out.push(hit));
}

/// Passes to `each` the closest pair of every piece whose surface is nearer `obstacle`
/// than `cutoff` and than the nearest passed so far plus `slack` (0: each one passed is
/// the nearest so far, the last the nearest of all).
fn scan(
    pieces: &[Piece],
    bound: &BodyBox,
    obstacle: &Obstacle,
    cutoff: f64,
    slack: f64,
    mut each: impl FnMut(BodyClosest),
) {
    let curve = match obstacle {
        Obstacle::Curve(c) => Some(c),
        Obstacle::Segment(s) => Some(s.as_curve()),
        _ => None,
    };
    // The curve's interval spheres that reach the body's box (bit k for sphere k; a curve
    // has at most 64 intervals). A sphere clear of the box is clear of every surface inside
    // it, so the usual far obstacle costs a few sphere tests and no per-piece work.
    let near = curve.map(|c| {
        let spheres = c.interval_spheres();
        debug_assert!(spheres.len() <= 64);
        let (lo, hi) = c.bounding_box();
        if bound.clear_of_box(&lo, &hi, cutoff) {
            return 0u64;
        }
        spheres
            .iter()
            .enumerate()
            .filter(|(_, (c, r))| !bound.clear_of(c, *r, cutoff))
            .fold(0u64, |m, (k, _)| m | (1 << k))
    });
    if near == Some(0) {
        return;
    }
    let mut limit = cutoff;
    for (i, p) in pieces.iter().enumerate() {
        // The backbone distance that would bring the surface within the limit.
        let reach_backbone = limit + p.radius;
        if let (Some(c), Some(mut mask)) = (curve, near) {
            // Cull by the curve's per-interval bounding spheres (the whole-curve sphere of
            // a long cane holds most of the arm), those that reach the box: skip the piece
            // when each is at least `limit` from the piece's surface. Squared, to spare a
            // square root per interval: |centre − c| ≥ r + L/2 + radius + limit.
            let spheres = c.interval_spheres();
            let mut far = true;
            while mask != 0 && far {
                let (c, r) = spheres[mask.trailing_zeros() as usize];
                mask &= mask - 1;
                let reach = r + p.half + reach_backbone;
                far = (p.centre - c).norm_squared() >= reach * reach;
            }
            if far {
                continue;
            }
        }
        let arc = std::slice::from_ref(&p.arc);
        if let Some(c) = closest_to_arcs_within(arc, obstacle, reach_backbone) {
            let surface = c.distance - p.radius;
            if surface < limit {
                limit = limit.min(surface + slack);
                each(BodyClosest {
                    closest: c.in_section(p.section),
                    rigid: p.rigid,
                    surface,
                    piece: i,
                });
            }
        }
    }
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
    for (i, p) in pieces.iter().enumerate() {
        let c = closest_to_arcs(std::slice::from_ref(&p.arc), obstacle);
        if best.is_none_or(|b| c.distance < b.closest.distance) {
            best = Some(BodyClosest {
                closest: c.in_section(p.section),
                rigid: p.rigid,
                surface: c.distance,
                piece: i,
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

    /// The box holds every piece (sampled), and the culled query agrees with the exact
    /// whole-body distance for canes from touching to far beyond the cutoff: a cull only
    /// skips what is provably at least `cutoff` away.
    #[test]
    fn culled_query_agrees_with_the_exact_distance() {
        use crate::distance::PolynomialCurve;
        let arm = SoftArm::blackberry();
        let configs = [
            [0.0166; 9],
            [
                0.016, 0.012, 0.020, 0.018, 0.015, 0.014, 0.017, 0.019, 0.013,
            ],
            [0.0, 0.03, 0.01, 0.03, 0.0, 0.02, 0.005, 0.03, 0.0],
        ];
        let cutoff = 0.071;
        let mut pieces = Vec::new();
        let (mut culled, mut near) = (0, 0);
        for q in &configs {
            placed_pieces_into(&arm, q, &mut pieces);
            let bound = BodyBox::around(&pieces);
            for p in &pieces {
                for k in 0..=20 {
                    let x = p.arc.point(k as f64 / 20.0);
                    assert!(!bound.clear_of(&x, 0.0, 1e-9), "{x:?} outside {bound:?}");
                    assert!((x - p.centre).norm() <= p.half + 1e-12);
                }
            }
            for k in 0..24 {
                let a = k as f64 * std::f64::consts::PI / 12.0;
                let radius = 0.02 + 0.01 * k as f64;
                let coeffs = [
                    Vec3::new(radius * a.cos(), radius * a.sin(), 0.0),
                    Vec3::new(0.0, 0.0, 1.0),
                    Vec3::new(0.03, 0.01, 0.0),
                ];
                let cane = Obstacle::Curve(PolynomialCurve::new(&coeffs, (0.0, 0.6)).unwrap());
                let exact = closest_body(&arm, q, &cane).unwrap().closest.distance;
                match closest_piece_within(&pieces, &bound, &cane, cutoff) {
                    Some(hit) => {
                        near += 1;
                        assert!((hit.closest.distance - exact).abs() < 1e-12);
                    }
                    None => {
                        culled += 1;
                        assert!(exact >= cutoff - 1e-12, "missed a cane at {exact}");
                    }
                }
            }
        }
        assert!(culled > 0 && near > 0, "{culled} culled, {near} near");
    }
}
