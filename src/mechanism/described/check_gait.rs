//! The `[gait]` table of a description (docs/model.md section 13): the stance and landing contacts, the
//! relabeling (a permutation of the coordinates), the sliding coordinate, the hip, the section and its start.

use toml::Spanned;

use super::checker::Checker;
use super::error::{DescriptionError, Problem};
use super::expr::Expr;
use super::format;
use super::intern;
use super::model::{Description, Gait, LegStroke, Motion, State, STOPPERS_LINE};

/// Positions fixed by the contact conditions on the section: the stance contact's `x` and `z`, the landing
/// contact's `z`.
pub const POSITION_CONDITIONS: usize = 3;

/// Velocities fixed by the stance contact held on the section: its `x` and `z`.
pub const VELOCITY_CONDITIONS: usize = 2;

/// The suffix of a velocity's name on the section.
pub const DOT: &str = "_dot";

/// The checked `[gait]` table of `d`.
pub fn gait(
    cx: &Checker,
    raw: &Spanned<format::Gait>,
    d: &Description,
) -> Result<Gait, DescriptionError> {
    let g = raw.get_ref();
    let contacts: Vec<&str> = d.contacts.iter().map(|c| c.name.as_str()).collect();
    let bodies: Vec<&str> = d.bodies.iter().map(|b| b.name.as_str()).collect();
    let field = |offset: usize, field: &'static str, reason: String| {
        cx.at(offset, Problem::Field { field, reason })
    };
    let (stance, lands) = (
        cx.find(&g.stance, &contacts, "contact")?,
        cx.find(&g.lands, &contacts, "contact")?,
    );
    if stance == lands {
        return Err(field(
            g.lands.span().start,
            "lands",
            "the landing contact is the stance contact".to_string(),
        ));
    }
    let shift = match &g.shift {
        Some(name) => Some(shift(cx, name, d)?),
        None => None,
    };
    let relabel = relabel(cx, &g.relabel, d)?;
    let strokes = match &g.strokes {
        Some(raw) => Some(strokes(cx, raw, d, (&relabel, [stance, lands]))?),
        None => None,
    };
    let fore = strokes.as_ref().map(|[fore, _]| fore.coordinate);
    let (section_names, section) = section(cx, &g.section, d, fore)?;
    let guess = guesses(cx, g, d, (&section_names, &section), fore)?;
    if g.start.get_ref().len() != section.len() {
        return Err(field(
            g.start.span().start,
            "start",
            format!(
                "{} values for a section of {}: {}",
                g.start.get_ref().len(),
                section.len(),
                section_names.join(", ")
            ),
        ));
    }
    Ok(Gait {
        stance,
        lands,
        relabel,
        strokes,
        shift,
        hip: cx.find(&g.hip, &bodies, "body")?,
        section_names,
        section,
        guess,
        start: g.start.get_ref().clone(),
    })
}

/// The guesses of the coordinates the contact conditions solve for: expressions over the parameters and the
/// section's positions, for coordinates neither on the section nor the fore leg's stroke (held at its
/// stopper).
fn guesses(
    cx: &Checker,
    g: &format::Gait,
    d: &Description,
    (section_names, section): (&[&'static str], &[(usize, bool)]),
    fore: Option<usize>,
) -> Result<Vec<(usize, Expr)>, DescriptionError> {
    let positions = section
        .iter()
        .zip(section_names)
        .filter(|((_, velocity), _)| !velocity)
        .map(|(_, n)| *n);
    let mut names: Vec<&str> = d.parameters.iter().map(|p| p.name).collect();
    names.extend(positions);
    let mut guess = Vec::new();
    for (name, value) in g.guess.iter().flat_map(|p| &p.0) {
        let k = cx.find(name, &d.coordinates, "coordinate")?;
        let given = if section.contains(&(k, false)) {
            Some("is on the section")
        } else if fore == Some(k) {
            Some("is the fore leg's stroke, at its stopper on the section")
        } else {
            None
        };
        if let Some(given) = given {
            return Err(cx.at(
                name.span().start,
                Problem::Field {
                    field: "guess",
                    reason: format!("`{}` {given}: it needs no guess", name.get_ref()),
                },
            ));
        }
        guess.push((k, cx.expr(value, &names)?));
    }
    Ok(guess)
}

/// A refusal of the `strokes` key at `offset`.
fn refuse_strokes(cx: &Checker, offset: usize, reason: String) -> DescriptionError {
    cx.at(
        offset,
        Problem::Field {
            field: "strokes",
            reason,
        },
    )
}

/// The legs' strokes: two free prismatic joints with an upper stopper and none below (the compliant walk holds
/// a leg at its upper stopper only), each moving its leg's contact (`tips`: the stance and the landing
/// contact), exchanged by the relabeling, and no other joint with stoppers.
fn strokes(
    cx: &Checker,
    raw: &Spanned<format::Strokes>,
    d: &Description,
    (relabel, tips): (&[usize], [usize; 2]),
) -> Result<[LegStroke; 2], DescriptionError> {
    let s = raw.get_ref();
    let fore = stroke(cx, d, &s.fore, tips[0])?;
    let rear = stroke(cx, d, &s.rear, tips[1])?;
    let (f, r) = (fore.coordinate, rear.coordinate);
    if f == r {
        return Err(refuse_strokes(
            cx,
            s.rear.span().start,
            "the fore and the rear leg's strokes are one joint".to_string(),
        ));
    }
    if relabel[f] != r || relabel[r] != f {
        return Err(refuse_strokes(
            cx,
            raw.span().start,
            format!(
                "the relabeling must exchange `{}` and `{}` (the legs exchange roles at a heel strike)",
                d.coordinates[f], d.coordinates[r]
            ),
        ));
    }
    let other = d.free_joints().find(|(_, j)| {
        j.stoppers.iter().any(Option::is_some) && j.coordinate != f && j.coordinate != r
    });
    if let Some((joint, _)) = other {
        return Err(refuse_strokes(
            cx,
            raw.span().start,
            format!(
                "joint `{}` has stoppers (line {}) but is no leg's stroke: the compliant walk stops only the \
                 legs' strokes",
                joint.name, joint.field_lines[STOPPERS_LINE]
            ),
        ));
    }
    Ok([fore, rear])
}

/// One leg's stroke `name`: a free prismatic joint with an upper stopper and none below, moving the contact
/// `tip`.
fn stroke(
    cx: &Checker,
    d: &Description,
    name: &Spanned<String>,
    tip: usize,
) -> Result<LegStroke, DescriptionError> {
    let k = cx.find(name, &d.coordinates, "coordinate")?;
    let n = name.get_ref();
    let refuse = |reason: String| refuse_strokes(cx, name.span().start, reason);
    let Some((joint, free)) = d.free_joints().find(|(_, f)| f.coordinate == k) else {
        return Err(refuse(format!("`{n}` is no free joint")));
    };
    if !matches!(joint.motion, Motion::Prismatic { .. }) {
        return Err(refuse(format!(
            "`{n}` is a revolute joint: a leg's stroke is a prismatic joint, the leg's length"
        )));
    }
    if free.stoppers[0].is_some() {
        return Err(refuse(format!(
            "`{n}` has a lower stopper (line {}): the compliant walk stops a leg at its upper stopper only, so a \
             lower one would be ignored",
            joint.field_lines[STOPPERS_LINE]
        )));
    }
    let Some(stopper) = free.stoppers[1].clone() else {
        return Err(refuse(format!(
            "`{n}` has no upper stopper: the compliant walk holds a leg at its stopper (give joint `{n}` \
             stoppers = {{ upper = ... }})"
        )));
    };
    if !moves(d, k, d.contacts[tip].body) {
        return Err(refuse(format!(
            "`{n}` does not move the contact `{}`: a stroke is the length of the leg whose tip that contact is \
             (`fore` the stance contact's, `rear` the landing contact's)",
            d.contacts[tip].name
        )));
    }
    Ok(LegStroke {
        coordinate: k,
        stopper,
    })
}

/// The relabeling as `new[i] = old[relabel[i]]`: each coordinate named once as a key and once as a value.
fn relabel(
    cx: &Checker,
    raw: &Spanned<format::Pairs<Spanned<String>>>,
    d: &Description,
) -> Result<Vec<usize>, DescriptionError> {
    let not = |offset: usize, reason: String| cx.at(offset, Problem::NotAPermutation { reason });
    let mut relabel: Vec<usize> = (0..d.coordinates.len()).collect();
    let (mut keys, mut values) = (Vec::new(), Vec::new());
    for (new, old) in &raw.get_ref().0 {
        let (k, v) = (
            cx.find(new, &d.coordinates, "coordinate")?,
            cx.find(old, &d.coordinates, "coordinate")?,
        );
        if values.contains(&v) {
            return Err(not(
                old.span().start,
                format!("`{}` is given to two coordinates", old.get_ref()),
            ));
        }
        keys.push(k);
        values.push(v);
        relabel[k] = v;
    }
    if let Some(missing) = values.iter().find(|v| !keys.contains(v)) {
        return Err(not(
            raw.span().start,
            format!(
                "`{}` gives its value but takes none: every coordinate named must both give and take",
                d.coordinates[*missing]
            ),
        ));
    }
    Ok(relabel)
}

/// Whether the free joint of `coordinate` lies on the path from `body` to the ground (the tree is checked).
fn moves(d: &Description, coordinate: usize, body: usize) -> bool {
    let mut next = Some(body);
    while let Some(child) = next {
        let Some(joint) = d.joints.iter().find(|j| j.child == child) else {
            return false;
        };
        if matches!(&joint.state, State::Free(f) if f.coordinate == coordinate) {
            return true;
        }
        next = joint.parent;
    }
    false
}

/// The sliding coordinate: a free prismatic joint from the ground.
fn shift(cx: &Checker, name: &Spanned<String>, d: &Description) -> Result<usize, DescriptionError> {
    let k = cx.find(name, &d.coordinates, "coordinate")?;
    let slides = d.joints.iter().any(|j| {
        matches!(j.motion, Motion::Prismatic { .. })
            && j.parent.is_none()
            && matches!(&j.state, State::Free(f) if f.coordinate == k)
    });
    if !slides {
        return Err(cx.at(
            name.span().start,
            Problem::Field {
                field: "shift",
                reason: format!(
                    "`{}` must be a free prismatic joint from the ground along the slope",
                    name.get_ref()
                ),
            },
        ));
    }
    Ok(k)
}

/// The section: names of coordinates and of velocities (`_dot`), such that the contact conditions fix the
/// others ([`POSITION_CONDITIONS`] positions, [`VELOCITY_CONDITIONS`] velocities), and with telescopic legs
/// the fore leg's stroke `fore` at its stopper, not extending (one position and one velocity more).
#[allow(clippy::type_complexity)]
fn section(
    cx: &Checker,
    raw: &Spanned<Vec<Spanned<String>>>,
    d: &Description,
    fore: Option<usize>,
) -> Result<(Vec<&'static str>, Vec<(usize, bool)>), DescriptionError> {
    let mut names = Vec::new();
    let mut section = Vec::new();
    for name in raw.get_ref() {
        let n = name.get_ref();
        let (base, velocity) = match n.strip_suffix(DOT) {
            Some(base) if d.coordinates.contains(&base) => (base, true),
            _ => (n.as_str(), false),
        };
        let k = d
            .coordinates
            .iter()
            .position(|c| *c == base)
            .ok_or_else(|| {
                cx.at(
                    name.span().start,
                    Problem::Unknown {
                        what: "coordinate",
                        name: n.clone(),
                        known: format!(
                            "{} and their velocities `NAME{DOT}`",
                            d.coordinates.join(", ")
                        ),
                    },
                )
            })?;
        let refused = if fore == Some(k) {
            Some(format!(
                "`{n}` is the fore leg's stroke or its rate: on the section that leg is at its stopper, not \
                 extending"
            ))
        } else if section.contains(&(k, velocity)) {
            Some(format!("`{n}` is named twice"))
        } else {
            None
        };
        if let Some(reason) = refused {
            return Err(cx.at(
                name.span().start,
                Problem::Field {
                    field: "section",
                    reason,
                },
            ));
        }
        names.push(intern(n));
        section.push((k, velocity));
    }
    let n = d.coordinates.len();
    let held = usize::from(fore.is_some());
    let free_positions = n - held - section.iter().filter(|(_, v)| !v).count();
    let free_velocities = n - held - section.iter().filter(|(_, v)| *v).count();
    if free_positions != POSITION_CONDITIONS || free_velocities != VELOCITY_CONDITIONS {
        return Err(cx.at(
            raw.span().start,
            Problem::Field {
                field: "section",
                reason: format!(
                    "it leaves {free_positions} coordinates and {free_velocities} velocities to the contact \
                     conditions, which fix {POSITION_CONDITIONS} and {VELOCITY_CONDITIONS} ({}): name {} \
                     coordinates and {} velocities",
                    if fore.is_some() {
                        "the stance contact at the origin, the landing contact on the ground and at rest; the fore \
                         leg's stroke is at its stopper"
                    } else {
                        "the stance contact at the origin and held, the landing contact on the ground"
                    },
                    n.saturating_sub(POSITION_CONDITIONS + held),
                    n.saturating_sub(VELOCITY_CONDITIONS + held)
                ),
            },
        ));
    }
    Ok((names, section))
}

/// With telescopic legs, the compliant walk takes contact point 0 as the stance leg's tip and 1 as the landing
/// leg's (`crate::mechanism::legged`): the contacts of `d` are reordered so, the others after them in the
/// file's order, and the gait's indices with them.
pub fn legs_first(d: &mut Description) {
    let Some(g) = d.gait.as_mut().filter(|g| g.strokes.is_some()) else {
        return;
    };
    let (stance, lands) = (g.stance, g.lands);
    let mut order = vec![stance, lands];
    order.extend((0..d.contacts.len()).filter(|i| *i != stance && *i != lands));
    d.contacts = order.iter().map(|&i| d.contacts[i].clone()).collect();
    (g.stance, g.lands) = (0, 1);
}
