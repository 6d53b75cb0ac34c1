//! The arm's body: the one description of the surfaces that must not touch a cane.
//!
//! Every clearance of the project measures this body: the harvest's planning and contact
//! gaps (`softarm.harvest.clearance`), the Cosserat rod's ground truth of contact
//! (`softarm.sim.cosserat.clearance`, on the rod's own centre line) and the resolver's
//! obstacle task ([`crate::Resolver::with_body`], piece by piece). It is
//!
//! - each section's arc, a tube of radius [`Body::section_radii`] about the backbone: the
//!   ring of actuators' radius `r_i` plus one actuator's, [`ACTUATOR_RADIUS`];
//! - each inner section's end plate (its rigid offset `b_i`, redundancy paper eq. 3), a
//!   cylinder of the section's radius;
//! - the gripper, a capsule of radius [`Body::gripper_radius`] along the end-effector's z
//!   axis from the distal arc's tip (`gripper_back` behind the end-effector frame: the
//!   distal offset) to the grasp point (`grasp_offset` ahead of it).
//!
//! The surface gap to an obstacle of radius ρ is `min over the pieces of (d_k − r_k) − ρ`,
//! with `d_k` the exact distance of the piece's backbone (an arc, or a straight segment:
//! an arc of zero curvature) from the obstacle's centre line ([`crate::distance`]).

use crate::arc::ArcParams;
use crate::chain::check_q;
use crate::chain::SectionModel;
use crate::distance::arc_point::PlacedArc;
use crate::distance::bodies::{placed_pieces_into, Piece};
use crate::distance::{closest_to_arcs_within, Closest, Obstacle};
use crate::error::{check_parameter, Error, Result};
use crate::kinematics::Kinematics;
use crate::math::Frame;

/// Radius (m) of one pneumatic artificial muscle (5/8" braided sleeve, section II-A): the
/// body reaches this far beyond the actuators' axes.
pub const ACTUATOR_RADIUS: f64 = 0.008;

/// Radius (m) of the gripper with its fingers, around its axis.
pub const GRIPPER_RADIUS: f64 = 0.025;

/// Radius (m) of a blackberry cane: the obstacle the clearances and the repulsion are
/// tuned for.
pub const CANE_RADIUS: f64 = 0.005;

/// Largest radius or length of the body's description (m): ten times
/// [`crate::Section::MAX_SIZE`], so that every valid arm has a body.
const MAX_SIZE: f64 = 1000.0;

/// Which part of the body a closest pair lies on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Part {
    /// A section's arc.
    Arc,
    /// The end plate after an inner section.
    Plate,
    /// The gripper, from the distal arc's tip to the grasp point.
    Gripper,
}

/// The smallest surface gap between the body and one obstacle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyGap {
    /// Surface gap (m): backbone distance less the piece's radius and the obstacle's;
    /// below zero the surfaces overlap.
    pub gap: f64,
    /// The backbone pair of that piece; `section` is the section the piece belongs to (the
    /// distal one for the gripper) and `s` the fraction along the piece.
    pub closest: Closest,
    /// The piece's kind.
    pub part: Part,
}

/// The arm's body (see the module's documentation).
#[derive(Debug, Clone, PartialEq)]
pub struct Body {
    section_radii: Vec<f64>,
    gripper_radius: f64,
    gripper_back: f64,
    grasp_offset: f64,
}

impl Body {
    /// A body from its radii (m, proximal first: each section's tube, the plate after it
    /// sharing it), the gripper's radius (m), how far its capsule starts behind the
    /// end-effector frame (`gripper_back`, m) and reaches ahead of it (`grasp_offset`, m).
    ///
    /// # Errors
    /// [`Error::Shape`] for no sections; [`Error::Parameter`] for a radius or a length
    /// that is not finite or not in [0, 1000] m.
    pub fn new(
        section_radii: Vec<f64>,
        gripper_radius: f64,
        gripper_back: f64,
        grasp_offset: f64,
    ) -> Result<Self> {
        if section_radii.is_empty() {
            return Err(Error::shape("section_radii", "at least one radius", "none"));
        }
        for &r in &section_radii {
            check_parameter("section_radii", r, 0.0, MAX_SIZE)?;
        }
        check_parameter("gripper_radius", gripper_radius, 0.0, MAX_SIZE)?;
        check_parameter("gripper_back", gripper_back, 0.0, MAX_SIZE)?;
        check_parameter("grasp_offset", grasp_offset, 0.0, MAX_SIZE)?;
        Ok(Body {
            section_radii,
            gripper_radius,
            gripper_back,
            grasp_offset,
        })
    }

    /// The body of `arm` with a gripper reaching `grasp_offset` (m) ahead of the
    /// end-effector frame: each section's ring radius plus [`ACTUATOR_RADIUS`], and a
    /// gripper of [`GRIPPER_RADIUS`] from the distal arc's tip (the distal offset behind
    /// the end-effector frame).
    ///
    /// # Errors
    /// [`Error::Parameter`] for a `grasp_offset` not in [0, 1000] m.
    pub fn for_arm(arm: &crate::SoftArm, grasp_offset: f64) -> Result<Self> {
        let sections = arm.sections();
        Body::new(
            sections
                .iter()
                .map(|s| s.radius + ACTUATOR_RADIUS)
                .collect(),
            GRIPPER_RADIUS,
            sections.last().map_or(0.0, |s| s.offset),
            grasp_offset,
        )
    }

    /// Each section's surface radius about its backbone (m), proximal first; an inner
    /// section's end plate has its section's.
    pub fn section_radii(&self) -> &[f64] {
        &self.section_radii
    }

    /// The gripper capsule's radius (m).
    pub fn gripper_radius(&self) -> f64 {
        self.gripper_radius
    }

    /// How far (m) behind the end-effector frame, along its z axis, the gripper starts.
    pub fn gripper_back(&self) -> f64 {
        self.gripper_back
    }

    /// How far (m) ahead of the end-effector frame, along its z axis, the gripper reaches.
    pub fn grasp_offset(&self) -> f64 {
        self.grasp_offset
    }

    /// The widest surface radius of the body (m): a tube of it about the whole backbone
    /// holds every piece.
    pub fn widest(&self) -> f64 {
        self.section_radii
            .iter()
            .fold(self.gripper_radius, |a, &b| a.max(b))
    }

    /// The bare backbone of an arm of `n_sections` sections: every radius 0 and no
    /// gripper beyond the distal arc (the body of a model that declares no radii, such as
    /// [`crate::ArcChain`]).
    pub fn bare(n_sections: usize) -> Self {
        Body {
            section_radii: vec![0.0; n_sections],
            gripper_radius: 0.0,
            gripper_back: 0.0,
            grasp_offset: 0.0,
        }
    }

    /// Writes the pieces of this body on `model` at `q` (already checked; `model` has as
    /// many sections as the body) into `out`, each with its radius: every arc, every inner
    /// end plate, then the gripper, a straight piece along the end-effector's z axis from
    /// `gripper_back` behind its frame to `grasp_offset` ahead (left out when both are 0:
    /// then it is the distal arc's tip). No allocation once `out` has the room.
    pub fn pieces_into<K: SectionModel + ?Sized>(
        &self,
        model: &K,
        q: &[f64],
        out: &mut Vec<Piece>,
    ) {
        placed_pieces_into(model, q, out);
        let last = model.n_sections() - 1;
        // The distal offset's piece, if any, is the last; the gripper replaces it.
        if out.last().is_some_and(|p| p.rigid) {
            out.pop();
        }
        for p in out.iter_mut() {
            p.radius = self.section_radii[p.section];
        }
        let length = self.gripper_back + self.grasp_offset;
        let Some(distal) = out.last() else {
            return;
        };
        if length <= 0.0 {
            return;
        }
        // The distal arc's tip frame; the end-effector frame is `offset` along its z.
        let tip = distal.arc.frame.compose(&distal.arc.arc.params.frame(1.0));
        let offset = model.section_state(last, &q[3 * last..3 * last + 3]).offset;
        let start = Frame {
            rot: tip.rot,
            pos: tip.pos + tip.rot.column(2) * (offset - self.gripper_back),
        };
        let straight = ArcParams {
            length,
            ux: 0.0,
            uy: 0.0,
        };
        let mut gripper = Piece::new(PlacedArc::new(start, straight), last, true);
        gripper.radius = self.gripper_radius;
        out.push(gripper);
    }

    /// The kind of piece `i` of [`Body::pieces_into`]'s `pieces`.
    pub fn part_of(&self, pieces: &[Piece], i: usize) -> Part {
        let p = &pieces[i];
        let last = self.section_radii.len() - 1;
        if !p.rigid {
            Part::Arc
        } else if p.section == last {
            Part::Gripper
        } else {
            Part::Plate
        }
    }

    /// The smallest surface gap between this body on `model` at `q` and `obstacle`, an
    /// obstacle of radius `obstacle_radius` (m) about its centre line. Exact: each piece's
    /// backbone distance is the exact one of [`crate::distance`]; a piece whose backbone
    /// is farther than the best gap plus its radius is skipped by the culled query.
    ///
    /// # Errors
    /// [`Error::Shape`] / [`Error::NonFinite`] for a bad `q`; [`Error::Shape`] for a model
    /// with another number of sections; [`Error::Parameter`] for an `obstacle_radius` not
    /// in [0, 1000] m.
    pub fn gap<K: Kinematics + ?Sized>(
        &self,
        model: &K,
        q: &[f64],
        obstacle: &Obstacle,
        obstacle_radius: f64,
    ) -> Result<BodyGap> {
        check_q(model, q)?;
        check_parameter("obstacle_radius", obstacle_radius, 0.0, MAX_SIZE)?;
        if model.n_sections() != self.section_radii.len() {
            return Err(Error::shape(
                "model",
                format!("{} sections, as the body", self.section_radii.len()),
                model.n_sections().to_string(),
            ));
        }
        let mut pieces = Vec::with_capacity(2 * model.n_sections());
        self.pieces_into(model, q, &mut pieces);
        let mut best: Option<BodyGap> = None;
        for (i, p) in pieces.iter().enumerate() {
            // Only a backbone closer than (best gap + radius) can improve on the best.
            let cutoff = best.map_or(f64::INFINITY, |b| b.gap + obstacle_radius + p.radius);
            let Some(c) = closest_to_arcs_within(std::slice::from_ref(&p.arc), obstacle, cutoff)
            else {
                continue;
            };
            let gap = c.distance - p.radius - obstacle_radius;
            if best.is_none_or(|b| gap < b.gap) {
                best = Some(BodyGap {
                    gap,
                    closest: c.in_section(p.section),
                    part: self.part_of(&pieces, i),
                });
            }
        }
        // The first piece is always measured (its cutoff is infinite).
        best.ok_or_else(|| Error::parameter("obstacle", f64::NAN, "has no closest point"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::distance::{PolynomialCurve, Segment};
    use crate::math::Vec3;
    use crate::SoftArm;

    /// A tiny deterministic generator (xorshift), to keep the tests free of dependencies.
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> f64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }
        fn range(&mut self, lo: f64, hi: f64) -> f64 {
            lo + (hi - lo) * self.next()
        }
    }

    /// Points of the body's pieces, each with its radius: `n` per piece.
    fn sampled_body(body: &Body, arm: &SoftArm, q: &[f64], n: usize) -> Vec<(Vec3, f64)> {
        let mut pieces = Vec::new();
        body.pieces_into(arm, q, &mut pieces);
        pieces
            .iter()
            .flat_map(|p| (0..=n).map(move |k| (p.arc.point(k as f64 / n as f64), p.radius)))
            .collect()
    }

    #[test]
    fn for_arm_declares_the_blackberry_body() {
        let body = Body::for_arm(&SoftArm::blackberry(), 0.03).unwrap();
        let want = [0.036, 0.030, 0.026];
        for (r, w) in body.section_radii().iter().zip(want) {
            assert!((r - w).abs() < 1e-15, "{r}");
        }
        assert_eq!(body.gripper_radius(), GRIPPER_RADIUS);
        assert_eq!(body.gripper_back(), 0.060);
        assert_eq!(body.grasp_offset(), 0.03);
        assert!((body.widest() - 0.036).abs() < 1e-15);
        assert!(Body::new(vec![], 0.0, 0.0, 0.0).is_err());
        assert!(Body::new(vec![f64::NAN], 0.0, 0.0, 0.0).is_err());
        assert!(Body::for_arm(&SoftArm::blackberry(), -0.01).is_err());
    }

    #[test]
    fn the_gripper_ends_at_the_grasp_point() {
        let arm = SoftArm::blackberry();
        let body = Body::for_arm(&arm, 0.03).unwrap();
        let q = [0.01, 0.02, 0.005, 0.015, 0.0, 0.02, 0.01, 0.01, 0.03];
        let mut pieces = Vec::new();
        body.pieces_into(&arm, &q, &mut pieces);
        assert_eq!(pieces.len(), 6); // 3 arcs, 2 plates, the gripper
        let last = pieces.last().unwrap();
        let (g, section, r) = (&last.arc, last.section, last.radius);
        assert_eq!(
            (section, body.part_of(&pieces, 5), r),
            (2, Part::Gripper, GRIPPER_RADIUS)
        );
        let ee = arm.forward(&q).unwrap();
        let z = Vec3::new(ee[(0, 2)], ee[(1, 2)], ee[(2, 2)]);
        let p = Vec3::new(ee[(0, 3)], ee[(1, 3)], ee[(2, 3)]);
        assert!((g.point(1.0) - (p + z * 0.03)).norm() < 1e-12);
        assert!((g.point(0.0) - (p - z * 0.06)).norm() < 1e-12);
    }

    /// The exact gap against brute force: both the body and the cane sampled densely. The
    /// exact gap is never above the sampled one, and below it by no more than the
    /// sampling's resolution.
    #[test]
    fn gap_agrees_with_brute_force_sampling() {
        let arm = SoftArm::blackberry();
        let body = Body::for_arm(&arm, 0.03).unwrap();
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        let (mut parts, mut cases) = ([0usize; 3], 0);
        for _ in 0..60 {
            let q: Vec<f64> = (0..9).map(|_| rng.range(0.0, 70.0 / 2100.0)).collect();
            let ee = arm.forward(&q).unwrap();
            let s = rng.range(0.0, 1.0);
            // A cane passing near a random point of the backbone or the gripper.
            let anchor = if rng.next() < 0.3 {
                let z = Vec3::new(ee[(0, 2)], ee[(1, 2)], ee[(2, 2)]);
                Vec3::new(ee[(0, 3)], ee[(1, 3)], ee[(2, 3)]) + z * rng.range(-0.06, 0.03)
            } else {
                arm.point(&q, (3.0 * s) as usize % 3, rng.next()).unwrap().0
            };
            let dir = Vec3::new(
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
            )
            .normalize();
            let side = dir.cross(&Vec3::new(0.3, -0.5, 0.8)).normalize();
            let centre = anchor + side * rng.range(0.0, 0.08);
            let seg = Segment::new(centre - dir * 0.15, centre + dir * 0.15).unwrap();
            let bend = side * rng.range(-0.2, 0.2);
            let curve =
                PolynomialCurve::new(&[centre - dir * 0.15, dir * 0.3, bend], (0.0, 1.0)).unwrap();
            for ob in [Obstacle::Segment(seg), Obstacle::Curve(curve)] {
                let exact = body.gap(&arm, &q, &ob, CANE_RADIUS).unwrap();
                let cane: Vec<Vec3> = match &ob {
                    Obstacle::Segment(s) => (0..=3000)
                        .map(|k| s.a() + (s.b() - s.a()) * (k as f64 / 3000.0))
                        .collect(),
                    Obstacle::Curve(c) => (0..=3000).map(|k| c.eval(k as f64 / 3000.0)).collect(),
                    _ => unreachable!(),
                };
                let brute = sampled_body(&body, &arm, &q, 400)
                    .iter()
                    .map(|(x, r)| {
                        cane.iter()
                            .map(|y| (x - y).norm())
                            .fold(f64::INFINITY, f64::min)
                            - r
                    })
                    .fold(f64::INFINITY, f64::min)
                    - CANE_RADIUS;
                assert!(
                    exact.gap <= brute + 1e-9,
                    "exact {} > sampled {brute}",
                    exact.gap
                );
                assert!(
                    brute - exact.gap < 2e-4,
                    "exact {} sampled {brute}",
                    exact.gap
                );
                parts[exact.part as usize] += 1;
                cases += 1;
            }
        }
        assert_eq!(cases, 120);
        assert!(parts.iter().all(|&n| n > 0), "closest parts {parts:?}");
    }

    #[test]
    fn gap_checks_its_inputs() {
        let arm = SoftArm::blackberry();
        let body = Body::for_arm(&arm, 0.03).unwrap();
        let ob = Obstacle::Point(Vec3::new(0.1, 0.0, 0.2));
        assert!(body.gap(&arm, &[0.0; 8], &ob, CANE_RADIUS).is_err());
        assert!(body.gap(&arm, &[0.0; 9], &ob, -1.0).is_err());
        let two = Body::new(vec![0.03, 0.03], GRIPPER_RADIUS, 0.0, 0.0).unwrap();
        assert!(two.gap(&arm, &[0.0; 9], &ob, CANE_RADIUS).is_err());
        // A point on the axis 1 m above the base: the gap is its distance to the grasp
        // point less the gripper's radius.
        let q = [0.0; 9];
        let top = Obstacle::Point(Vec3::new(0.0, 0.0, 1.0));
        let g = body.gap(&arm, &q, &top, 0.0).unwrap();
        let reach = 0.45 + 0.012 + 0.012 + 0.06 + 0.03;
        assert_eq!(g.part, Part::Gripper);
        assert!(
            (g.gap - (1.0 - reach - GRIPPER_RADIUS)).abs() < 1e-12,
            "{}",
            g.gap
        );
    }
}
