//! What a drawing of a described walker shows (`vrw simulate`, `plot`, `animate`; docs/model.md section 13):
//! its bodies' centres of mass (the bodies that have mass), its contacts, and its hinges (the revolute joints),
//! each centre and contact linked to the hinge its body hangs from (the nearest revolute joint on the way from
//! its body to the ground). A compass gait is then its two legs from the hip with their masses; a telescopic
//! leg is a line from the hip to its tip, whatever the sliders between.

use nalgebra::{SVector, Vector2};

use super::kinematics::frames;
use super::model::{Description, Motion};
use super::{Described, Mechanism};

/// The points of a drawing, their links, and which are masses and which contacts.
#[derive(Debug, Clone, PartialEq)]
pub struct Drawing {
    /// The points' names: the bodies with mass, then the contacts, then the hinges (`JOINT_hinge`).
    pub points: Vec<String>,
    /// Links `[from, to]` (indices in `points`): from a hinge to a centre or a contact below it.
    pub links: Vec<[usize; 2]>,
    /// The points that carry mass.
    pub masses: Vec<usize>,
    /// The contacts.
    pub contacts: Vec<usize>,
}

/// The revolute joint nearest to `body` on its way to the ground (the joint whose child it is, or its
/// parent's, ...), by index in the description's joints.
fn hinge_of(d: &Description, body: usize) -> Option<usize> {
    let mut at = body;
    // Each body has one joint from its parent (the tree): at most as many steps as joints.
    for _ in 0..=d.joints.len() {
        let (k, joint) = d.joints.iter().enumerate().find(|(_, j)| j.child == at)?;
        if matches!(joint.motion, Motion::Revolute { .. }) {
            return Some(k);
        }
        at = joint.parent?;
    }
    None
}

impl<const N: usize> Described<N> {
    /// The bodies with mass at the parameters' values.
    fn massive(&self) -> Vec<usize> {
        let c = self.constants_f64();
        (0..self.description.bodies.len())
            .filter(|&b| c.of(&self.description.bodies[b].mass) > 0.0)
            .collect()
    }

    /// The hinges drawn: the revolute joints some massive body or contact hangs from, in the joints' order.
    fn hinges(&self, massive: &[usize]) -> Vec<usize> {
        let d = &self.description;
        let bodies = massive
            .iter()
            .copied()
            .chain(d.contacts.iter().map(|c| c.body));
        let mut used: Vec<usize> = bodies.filter_map(|b| hinge_of(d, b)).collect();
        used.sort_unstable();
        used.dedup();
        used
    }

    /// What the drawing shows (see the module documentation).
    pub fn drawing(&self) -> Drawing {
        let d = &self.description;
        let massive = self.massive();
        let hinges = self.hinges(&massive);
        let mut points: Vec<String> = massive.iter().map(|&b| d.bodies[b].name.clone()).collect();
        points.extend(d.contacts.iter().map(|c| c.name.clone()));
        points.extend(
            hinges
                .iter()
                .map(|&k| format!("{}_hinge", d.joints[k].name)),
        );
        let contacts: Vec<usize> = (massive.len()..massive.len() + d.contacts.len()).collect();
        let hinge_point = |body: usize| {
            let k = hinge_of(d, body)?;
            let at = hinges.iter().position(|&h| h == k)?;
            Some(massive.len() + d.contacts.len() + at)
        };
        let bodies = massive
            .iter()
            .copied()
            .chain(d.contacts.iter().map(|c| c.body));
        let links = bodies
            .enumerate()
            .filter_map(|(point, body)| Some([hinge_point(body)?, point]))
            .collect();
        Drawing {
            points,
            links,
            masses: (0..massive.len()).collect(),
            contacts,
        }
    }

    /// The drawing's points at `q` ([`Described::drawing`]'s order), in the slope frame.
    pub fn drawing_points(&self, q: &SVector<f64, N>) -> Vec<[f64; 2]> {
        let d = &self.description;
        let c = self.constants_f64();
        let frames = frames(d, &c, q, &SVector::zeros());
        let massive = self.massive();
        let at = |body: usize, r: Vector2<f64>| {
            let p = frames[body].point(r).position;
            [p.x, p.y]
        };
        let centres = massive
            .iter()
            .map(|&b| at(b, c.vector(&d.bodies[b].centre)));
        let contacts = d.contacts.iter().map(|k| at(k.body, c.vector(&k.at)));
        let hinges = self
            .hinges(&massive)
            .into_iter()
            .map(|k| at(d.joints[k].child, Vector2::zeros()));
        centres.chain(contacts).chain(hinges).collect()
    }
}
