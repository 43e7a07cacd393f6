//! What a drawing of a described walker shows (`vrw simulate`, `plot`, `animate`; docs/model.md section 13):
//! its bodies' centres of mass (the bodies that have mass), its contacts, its hinges (the revolute joints) and
//! its springs (the prismatic joints with a spring or a damper). Each centre and contact is linked to the
//! joint its body hangs from (the nearest revolute or sprung joint on the way from its body to the ground): to
//! a hinge's point, or to the lower end of a spring. A spring is drawn as a coil along its joint's line, between
//! a point fixed on the parent (half the joint's reference length from the joint's place) and a point that
//! moves with the child (a quarter of it short of the child's frame), with a link from the hinge above it to
//! its upper end: a sleeve, the coil, a rod. The reference length is the upper stopper, else the spring's rest
//! value (none: the coil spans the joint). A compass gait is then its two legs from the hip with their masses;
//! a telescopic leg a sleeve from the hip, the spring, and a rod to its tip, as the built-in `telescopic` walker
//! is drawn.

use nalgebra::{SVector, Vector2};

use super::kinematics::{frames, Frame, Values};
use super::model::{Description, Motion, State};
use super::{Described, Mechanism};

/// The points of a drawing, their links, and which are masses, which contacts and which springs.
#[derive(Debug, Clone, PartialEq)]
pub struct Drawing {
    /// The points' names: the bodies with mass, then the contacts, then the hinges (`JOINT_hinge`), then each
    /// spring's ends (`JOINT_spring_top`, `JOINT_spring_bottom`).
    pub points: Vec<String>,
    /// Links `[from, to]` (indices in `points`): from a hinge or a spring's lower end to a centre or a contact
    /// below it, and from a hinge to the upper end of a spring below it.
    pub links: Vec<[usize; 2]>,
    /// The points that carry mass.
    pub masses: Vec<usize>,
    /// The contacts.
    pub contacts: Vec<usize>,
    /// The springs (with their dampers) `[top, bottom]`, drawn as coils.
    pub springs: Vec<[usize; 2]>,
}

/// Is joint `k` drawn as a spring: a free prismatic joint with a spring or a damper?
fn sprung(d: &Description, k: usize) -> bool {
    let joint = &d.joints[k];
    let acted = match &joint.state {
        State::Free(f) => f.spring.is_some() || f.damper.is_some(),
        State::Fixed(_) => false,
    };
    acted && matches!(joint.motion, Motion::Prismatic { .. })
}

/// The joint `body` hangs from in the drawing: the revolute or sprung joint nearest to it on its way to the
/// ground (the joint whose child it is, or its parent's, ...), by index in the description's joints.
fn hanger(d: &Description, body: usize) -> Option<usize> {
    let mut at = body;
    // Each body has one joint from its parent (the tree): at most as many steps as joints.
    for _ in 0..=d.joints.len() {
        let (k, joint) = d.joints.iter().enumerate().find(|(_, j)| j.child == at)?;
        if matches!(joint.motion, Motion::Revolute { .. }) || sprung(d, k) {
            return Some(k);
        }
        at = joint.parent?;
    }
    None
}

/// What a drawing is made of, before its points are named or placed.
struct Parts {
    /// The bodies with mass.
    massive: Vec<usize>,
    /// The hinges drawn: the revolute joints something hangs from, in the joints' order.
    hinges: Vec<usize>,
    /// The sprung joints, in the joints' order.
    springs: Vec<usize>,
}

impl Parts {
    /// The point a body's centre or contact is linked to: its hanger's hinge, or its spring's lower end.
    fn hung_from(&self, d: &Description, contacts: usize, body: usize) -> Option<usize> {
        let k = hanger(d, body)?;
        let before_hinges = self.massive.len() + contacts;
        match self.springs.iter().position(|&s| s == k) {
            Some(s) => Some(before_hinges + self.hinges.len() + 2 * s + 1),
            None => Some(before_hinges + self.hinges.iter().position(|&h| h == k)?),
        }
    }
}

impl<const N: usize> Described<N> {
    /// The bodies with mass at the parameters' values.
    fn massive(&self) -> Vec<usize> {
        let c = self.constants_f64();
        (0..self.description.bodies.len())
            .filter(|&b| c.of(&self.description.bodies[b].mass) > 0.0)
            .collect()
    }

    /// The parts of the drawing (see the module documentation).
    fn parts(&self) -> Parts {
        let d = &self.description;
        let massive = self.massive();
        let springs: Vec<usize> = (0..d.joints.len()).filter(|&k| sprung(d, k)).collect();
        let bodies = massive
            .iter()
            .copied()
            .chain(d.contacts.iter().map(|c| c.body))
            .chain(springs.iter().filter_map(|&k| d.joints[k].parent));
        let mut hinges: Vec<usize> = bodies
            .filter_map(|b| hanger(d, b))
            .filter(|&k| !sprung(d, k))
            .collect();
        hinges.sort_unstable();
        hinges.dedup();
        Parts {
            massive,
            hinges,
            springs,
        }
    }

    /// What the drawing shows (see the module documentation).
    pub fn drawing(&self) -> Drawing {
        let d = &self.description;
        let parts = self.parts();
        let (massive, contacts) = (&parts.massive, d.contacts.len());
        let mut points: Vec<String> = massive.iter().map(|&b| d.bodies[b].name.clone()).collect();
        points.extend(d.contacts.iter().map(|c| c.name.clone()));
        points.extend(
            parts
                .hinges
                .iter()
                .map(|&k| format!("{}_hinge", d.joints[k].name)),
        );
        let first_spring = points.len();
        for &k in &parts.springs {
            let name = &d.joints[k].name;
            points.extend([
                format!("{name}_spring_top"),
                format!("{name}_spring_bottom"),
            ]);
        }
        let bodies = massive
            .iter()
            .copied()
            .chain(d.contacts.iter().map(|c| c.body));
        let mut links: Vec<[usize; 2]> = bodies
            .enumerate()
            .filter_map(|(point, body)| Some([parts.hung_from(d, contacts, body)?, point]))
            .collect();
        let tops = parts.springs.iter().enumerate().filter_map(|(s, &k)| {
            let above = parts.hung_from(d, contacts, d.joints[k].parent?)?;
            Some([above, first_spring + 2 * s])
        });
        links.extend(tops);
        Drawing {
            points,
            links,
            masses: (0..massive.len()).collect(),
            contacts: (massive.len()..massive.len() + contacts).collect(),
            springs: (0..parts.springs.len())
                .map(|s| [first_spring + 2 * s, first_spring + 2 * s + 1])
                .collect(),
        }
    }

    /// The drawing's points at `q` ([`Described::drawing`]'s order), in the slope frame.
    pub fn drawing_points(&self, q: &SVector<f64, N>) -> Vec<[f64; 2]> {
        let d = &self.description;
        let c = self.constants_f64();
        let frames = frames(d, &c, q, &SVector::zeros());
        let parts = self.parts();
        let at = |body: usize, r: Vector2<f64>| {
            let p = frames[body].point(r).position;
            [p.x, p.y]
        };
        let centres = parts
            .massive
            .iter()
            .map(|&b| at(b, c.vector(&d.bodies[b].centre)));
        let contacts = d.contacts.iter().map(|k| at(k.body, c.vector(&k.at)));
        let hinges = parts
            .hinges
            .iter()
            .map(|&k| at(d.joints[k].child, Vector2::zeros()));
        let springs = parts
            .springs
            .iter()
            .flat_map(|&k| spring_ends(d, (&c, &frames), k, q));
        centres
            .chain(contacts)
            .chain(hinges)
            .chain(springs)
            .collect()
    }
}

/// The ends of the sprung joint `k`'s coil at `q` (see the module documentation): half its reference length
/// along it from its place on the parent, and a quarter of it short of the child's frame.
fn spring_ends<const N: usize>(
    d: &Description,
    (c, frames): (&Values<f64>, &[Frame<f64, N>]),
    k: usize,
    q: &SVector<f64, N>,
) -> [[f64; 2]; 2] {
    let joint = &d.joints[k];
    let (Motion::Prismatic { direction }, State::Free(free)) = (&joint.motion, &joint.state) else {
        return [[f64::NAN; 2]; 2];
    };
    let reference = match (&free.stoppers[1], &free.spring) {
        (Some(upper), _) => c.of(upper).abs(),
        (None, Some((_, rest))) => c.of(rest).abs(),
        (None, None) => 0.0,
    };
    let parent = joint.parent.map_or_else(Frame::ground, |p| frames[p]);
    let (place, along) = (c.vector(&joint.at), c.vector(direction));
    let end = |length: f64| {
        let p = parent.point(place + along * length).position;
        [p.x, p.y]
    };
    [
        end(0.5 * reference),
        end(q[free.coordinate] - 0.25 * reference),
    ]
}
