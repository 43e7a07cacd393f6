//! The `[gait]` table of a description (docs/model.md section 13): the stance and landing contacts, the
//! relabeling (a permutation of the coordinates), the sliding coordinate, the hip, the section and its start.

use toml::Spanned;

use super::checker::Checker;
use super::error::{DescriptionError, Problem};
use super::format;
use super::intern;
use super::model::{Description, Gait, Motion, State};

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
    let (section_names, section) = section(cx, &g.section, d)?;
    let positions: Vec<&str> = section
        .iter()
        .zip(&section_names)
        .filter(|((_, velocity), _)| !velocity)
        .map(|(_, n)| *n)
        .collect();
    let mut names: Vec<&str> = d.parameters.iter().map(|p| p.name).collect();
    names.extend(&positions);
    let mut guess = Vec::new();
    for (name, value) in g.guess.iter().flat_map(|p| &p.0) {
        let k = cx.find(name, &d.coordinates, "coordinate")?;
        if section.contains(&(k, false)) {
            return Err(field(
                name.span().start,
                "guess",
                format!("`{}` is on the section: it needs no guess", name.get_ref()),
            ));
        }
        guess.push((k, cx.expr(value, &names)?));
    }
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
        relabel: relabel(cx, &g.relabel, d)?,
        shift,
        hip: cx.find(&g.hip, &bodies, "body")?,
        section_names,
        section,
        guess,
        start: g.start.get_ref().clone(),
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
/// others ([`POSITION_CONDITIONS`] positions, [`VELOCITY_CONDITIONS`] velocities).
#[allow(clippy::type_complexity)]
fn section(
    cx: &Checker,
    raw: &Spanned<Vec<Spanned<String>>>,
    d: &Description,
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
        if section.contains(&(k, velocity)) {
            return Err(cx.at(
                name.span().start,
                Problem::Field {
                    field: "section",
                    reason: format!("`{n}` is named twice"),
                },
            ));
        }
        names.push(intern(n));
        section.push((k, velocity));
    }
    let n = d.coordinates.len();
    let free_positions = n - section.iter().filter(|(_, v)| !v).count();
    let free_velocities = n - section.iter().filter(|(_, v)| *v).count();
    if free_positions != POSITION_CONDITIONS || free_velocities != VELOCITY_CONDITIONS {
        return Err(cx.at(
            raw.span().start,
            Problem::Field {
                field: "section",
                reason: format!(
                    "it leaves {free_positions} coordinates and {free_velocities} velocities to the contact \
                     conditions, which fix {POSITION_CONDITIONS} and {VELOCITY_CONDITIONS} (the stance contact at \
                     the origin and held, the landing contact on the ground): name {} coordinates and {} velocities",
                    n.saturating_sub(POSITION_CONDITIONS),
                    n.saturating_sub(VELOCITY_CONDITIONS)
                ),
            },
        ));
    }
    Ok((names, section))
}
