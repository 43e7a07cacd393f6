//! Tests of a description's refusals: every bad description named by its file, its line and its problem
//! (docs/model.md section 13).

use super::tests::PENDULUM;
use super::{parse, AnyDescribed};

/// Every bad description is refused with the line of the problem and what it is.
#[test]
fn bad_descriptions_name_the_line_and_the_problem() {
    let base = PENDULUM;
    // Each bad line is marked `# HERE`: the error must name it.
    let cases: Vec<(String, &str)> = vec![
        (
            base.replace("child = \"cart\"", "child = \"base\" # HERE"),
            "body `base` has two parents",
        ),
        (
            base.replace(
                "parent = \"ground\"\nchild = \"base\"",
                "parent = \"flag\" # HERE\nchild = \"base\"",
            ),
            "cycle",
        ),
        (
            base.replace("body = \"flag\"", "body = \"flagg\" # HERE"),
            "unknown body `flagg`",
        ),
        (
            base.replace("mass = 0.3", "mass = -0.3 # HERE"),
            "the mass of body `mount` is -0.3",
        ),
        (
            base.replace("inertia = 0.02", "inertia = \"-m\" # HERE"),
            "the inertia of body `arm` is -1.3",
        ),
        (
            base.replace(
                "kind = \"revolute\"\nparent = \"mount\"",
                "kind = \"hinge\" # HERE\nparent = \"mount\"",
            ),
            "unknown variant `hinge`",
        ),
        (
            base.replace("mass = \"m\"", "mass = \"m * n\" # HERE"),
            "unknown parameter `n`",
        ),
        (
            base.replace(
                "centre = [0, -0.2]",
                "centre = [0, -0.2]\ncolour = \"red\" # HERE",
            ),
            "unknown field `colour`",
        ),
        (
            base.replace("direction = [0.6, -0.8]", "direction = [0.6, 0.6] # HERE"),
            "unit vector",
        ),
        (
            base.replace(
                "stoppers = { lower = 0.2, upper = 1.5 }",
                "stoppers = { lower = 2, upper = 1.5 } # HERE",
            ),
            "lower stopper",
        ),
        (
            base.replace(
                "fixed = 0.3",
                "fixed = 0.3\ndamper = { coefficient = 1 } # HERE",
            ),
            "only a free joint",
        ),
        (
            base.replace("slope = 0.2\n", "")
                .replace("[parameters]", "[parameters] # HERE"),
            "`slope` and `gravity`",
        ),
        (
            base.replace("m = 1.3", "m = { value = -1.3, positive = true } # HERE"),
            "the default of `m`",
        ),
        (
            base.replace("name = \"arm\"", "name = \"cart\" # HERE"),
            "body name `cart` is used twice",
        ),
        (
            base.replace(
                "[[contacts]]",
                "[[contacts]]\nname = \"heel\"\nbody = \"nobody\" # HERE\n[[contacts]]",
            ),
            "unknown body `nobody`",
        ),
        (
            base.replace("mass = \"m\"", "mass = \"(m\" # HERE"),
            "not closed",
        ),
        (
            base.replace(
                "[[bodies]]\nname = \"base\"",
                "[[bodies]]\nname = \"loose\" # HERE\n[[bodies]]\nname = \"base\"",
            ),
            "the child of no joint",
        ),
    ];
    for (text, needle) in cases {
        let line = 1 + text[..text.find("# HERE").unwrap()].matches('\n').count();
        let e = parse("bad.toml", &text).unwrap_err().to_string();
        assert!(
            e.starts_with(&format!("bad.toml line {line}: ")) && e.contains(needle),
            "want line {line} and {needle:?}: {e}"
        );
    }
}

/// The `[gait]` table's refusals, at their lines: a relabeling that is not a permutation, an unknown contact, a
/// section the contact conditions cannot complete, a start of the wrong length; and more coordinates than the
/// dispatch supports.
#[test]
fn bad_gait_tables_and_too_many_coordinates_name_their_line() {
    let compass =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/models/compass.toml"))
            .unwrap();
    let relabel = "relabel = { theta1 = \"theta2\", theta2 = \"theta1\" }";
    let cases: Vec<(String, &str)> = vec![
        (
            compass.replace(relabel, "relabel = { theta1 = \"theta2\" } # HERE"),
            "not a permutation of the coordinates: `theta2` gives its value but takes none",
        ),
        (
            compass.replace(
                relabel,
                "relabel = { theta1 = \"theta2\", theta2 = \"theta2\" } # HERE",
            ),
            "not a permutation of the coordinates: `theta2` is given to two coordinates",
        ),
        (
            compass.replace(
                relabel,
                "relabel = { theta1 = \"theta3\", theta3 = \"theta1\" } # HERE",
            ),
            "unknown coordinate `theta3`",
        ),
        (
            compass.replace("lands = \"foot2\"", "lands = \"foot3\" # HERE"),
            "unknown contact `foot3`",
        ),
        (
            compass.replace(
                "section = [\"theta1\", \"theta1_dot\", \"theta2_dot\"]",
                "section = [\"theta1\", \"theta1_dot\"] # HERE",
            ),
            "name 1 coordinates and 2 velocities",
        ),
        (
            compass.replace(
                "start = [0.2710, -1.0924, -0.3774]",
                "start = [0.2710] # HERE",
            ),
            "1 values for a section of 3",
        ),
        (
            compass.replace("shift = \"x\"", "shift = \"theta1\" # HERE"),
            "a free prismatic joint from the ground",
        ),
    ];
    for (text, needle) in cases {
        let line = 1 + text[..text.find("# HERE").unwrap()].matches('\n').count();
        let e = parse("bad.toml", &text).unwrap_err().to_string();
        assert!(
            e.starts_with(&format!("bad.toml line {line}: ")) && e.contains(needle),
            "want line {line} and {needle:?}: {e}"
        );
    }
    // Nine free joints: a chain of sliders.
    let mut chain = String::from("name = \"chain\"\n[parameters]\nslope = 0.1\ngravity = 9.81\n");
    for k in 0..9 {
        let parent = if k == 0 {
            "ground".to_string()
        } else {
            format!("b{}", k - 1)
        };
        chain += &format!("[[bodies]]\nname = \"b{k}\"\nmass = 1\n");
        let mark = if k == 8 { " # HERE" } else { "" };
        chain += &format!("[[joints]]{mark}\nname = \"s{k}\"\nkind = \"prismatic\"\nparent = \"{parent}\"\nchild = \"b{k}\"\ndirection = [1, 0]\n");
    }
    let line = 1 + chain[..chain.find("# HERE").unwrap()].matches('\n').count();
    let e = parse("chain.toml", &chain).unwrap_err().to_string();
    assert!(
        e.starts_with(&format!(
            "chain.toml line {line}: 9 coordinates (free joints): at most 8"
        )),
        "{e}"
    );
    // Eight are taken, as an N = 8 walker.
    let eight = chain.replacen(
        "[[joints]] # HERE\nname = \"s8\"",
        "[[joints]]\nname = \"s8\"\nfixed = 0.5",
        1,
    );
    assert!(matches!(
        parse("chain.toml", &eight).unwrap(),
        AnyDescribed::N8(_)
    ));
}

/// The refusals of a `[gait]` table with telescopic legs, at their lines: a stroke that is not a free prismatic
/// joint of its leg with an upper stopper (and none below), strokes the relabeling does not exchange, another
/// joint with stoppers, the fore leg's stroke on the section or guessed, a section of the wrong size, an
/// unknown key.
#[test]
fn bad_strokes_name_their_line() {
    let telescopic = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/models/telescopic.toml"
    ))
    .unwrap();
    let strokes = "strokes = { fore = \"L1\", rear = \"L2\" }";
    let marked = format!("{strokes} # HERE");
    let stoppers = "stoppers = { upper = \"stopper_length\" }\n";
    let section = "section = [\"theta1\", \"L2\", \"theta1_dot\", \"theta2_dot\", \"L2_dot\"]";
    let guess = "guess = { theta2 = \"-theta1\" }";
    let cases: Vec<(String, &str)> = vec![
        (
            telescopic.replace(
                strokes,
                "strokes = { fore = \"theta1\", rear = \"L2\" } # HERE",
            ),
            "`theta1` is a revolute joint: a leg's stroke is a prismatic joint",
        ),
        (
            telescopic
                .replacen(stoppers, "", 1)
                .replace(strokes, &marked),
            "`L1` has no upper stopper",
        ),
        (
            telescopic
                .replacen(
                    stoppers,
                    "stoppers = { lower = 0.5, upper = \"stopper_length\" }\n",
                    1,
                )
                .replace(strokes, &marked),
            "`L1` has a lower stopper",
        ),
        (
            telescopic.replace(strokes, "strokes = { fore = \"L1\", rear = \"L1\" } # HERE"),
            "`L1` does not move the contact `foot2`",
        ),
        (
            telescopic.replace(strokes, "strokes = { fore = \"L2\", rear = \"L1\" } # HERE"),
            "`L2` does not move the contact `foot1`",
        ),
        (
            telescopic.replace(strokes, "strokes = { fore = \"L3\", rear = \"L2\" } # HERE"),
            "unknown coordinate `L3`",
        ),
        (
            telescopic.replace(
                strokes,
                "strokes = { fore = \"L1\", rear = \"L2\", side = \"x\" } # HERE",
            ),
            "unknown field `side`",
        ),
        (
            telescopic
                .replace(
                    "relabel = { theta1 = \"theta2\", theta2 = \"theta1\", L1 = \"L2\", L2 = \"L1\" }",
                    "relabel = { theta1 = \"theta2\", theta2 = \"theta1\" }",
                )
                .replace(strokes, &marked),
            "the relabeling must exchange `L1` and `L2`",
        ),
        (
            telescopic
                .replacen(
                    "angle = \"absolute\"\n",
                    "angle = \"absolute\"\nstoppers = { upper = 1.2 }\n",
                    1,
                )
                .replace(strokes, &marked),
            "joint `theta1` has stoppers",
        ),
        (
            telescopic.replace(
                section,
                "section = [\"theta1\", \"L1\", \"theta1_dot\", \"theta2_dot\", \"L2_dot\"] # HERE",
            ),
            "`L1` is the fore leg's stroke or its rate",
        ),
        (
            telescopic.replace(
                section,
                "section = [\"theta1\", \"L2\", \"theta1_dot\", \"theta2_dot\"] # HERE",
            ),
            "name 2 coordinates and 3 velocities",
        ),
        (
            telescopic.replace(guess, "guess = { theta2 = \"-theta1\", L1 = 0.9 } # HERE"),
            "`L1` is the fore leg's stroke, at its stopper on the section: it needs no guess",
        ),
    ];
    for (text, needle) in cases {
        let line = 1 + text[..text.find("# HERE").unwrap()].matches('\n').count();
        let e = parse("bad.toml", &text).unwrap_err().to_string();
        assert!(
            e.starts_with(&format!("bad.toml line {line}: ")) && e.contains(needle),
            "want line {line} and {needle:?}: {e}"
        );
    }
}
