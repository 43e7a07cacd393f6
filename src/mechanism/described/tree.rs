//! The joints of a description as a tree rooted at the ground (docs/model.md section 13): every body the child
//! of exactly one joint, no cycle, and the joints ordered so that each comes after the one that places its
//! parent.

use toml::Spanned;

use super::checker::Checker;
use super::error::{DescriptionError, Problem};
use super::format;
use super::model::{Body, Joint};

/// `joints` ordered from the ground outward, or the first break of the tree: a body with two parents, a body
/// no joint holds, a cycle.
pub fn ordered(
    cx: &Checker,
    joints: Vec<Joint>,
    bodies: &[Body],
    raw: &[Spanned<format::Joint>],
) -> Result<Vec<Joint>, DescriptionError> {
    // The joint that holds each body.
    let mut holder: Vec<Option<usize>> = vec![None; bodies.len()];
    for (k, j) in joints.iter().enumerate() {
        if let Some(first) = holder[j.child] {
            return Err(cx.at(
                raw[k].get_ref().child.span().start,
                Problem::TwoParents {
                    body: bodies[j.child].name.clone(),
                    first: joints[first].name.clone(),
                    line: joints[first].line,
                },
            ));
        }
        holder[j.child] = Some(k);
    }
    if let Some(b) = holder.iter().position(Option::is_none) {
        return Err(DescriptionError::At {
            file: cx.file.to_string(),
            line: bodies[b].lines[0].min(bodies[b].lines[1]),
            problem: Problem::Unattached {
                body: bodies[b].name.clone(),
            },
        });
    }
    // Breadth first from the ground: a joint is placed once its parent is.
    let mut placed = vec![false; bodies.len()];
    let mut order: Vec<usize> = Vec::with_capacity(joints.len());
    let mut progress = true;
    while progress {
        progress = false;
        for (k, j) in joints.iter().enumerate() {
            if !placed[j.child] && j.parent.is_none_or(|p| placed[p]) {
                placed[j.child] = true;
                order.push(k);
                progress = true;
            }
        }
    }
    if let Some(k) = (0..joints.len()).find(|k| !order.contains(k)) {
        return Err(cx.at(
            raw[k].get_ref().parent.span().start,
            Problem::Cycle {
                cycle: cycle(&joints, &holder, bodies, joints[k].child),
            },
        ));
    }
    let mut slots: Vec<Option<Joint>> = joints.into_iter().map(Some).collect();
    Ok(order.into_iter().filter_map(|k| slots[k].take()).collect())
}

/// The bodies of the cycle reached by following parents from `body`, as `a -> b -> a`.
fn cycle(joints: &[Joint], holder: &[Option<usize>], bodies: &[Body], body: usize) -> String {
    let mut path = vec![body];
    let mut b = body;
    while let Some(p) = holder[b].and_then(|k| joints[k].parent) {
        if let Some(at) = path.iter().position(|x| *x == p) {
            let mut names: Vec<&str> = path[at..]
                .iter()
                .map(|x| bodies[*x].name.as_str())
                .collect();
            names.push(&bodies[p].name);
            return names.join(" <- ");
        }
        path.push(p);
        b = p;
    }
    // Unreachable for a cycle, kept total: the path followed.
    path.iter()
        .map(|x| bodies[*x].name.as_str())
        .collect::<Vec<_>>()
        .join(" <- ")
}
