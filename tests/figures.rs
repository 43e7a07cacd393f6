//! `vrw animate` and `vrw plot` end to end, on the directories `vrw simulate` and `vrw gait` write: the GIF
//! decodes with the planned number of frames, the PNGs have their documented sizes, and bad input gets an
//! error naming the problem. Only structure is checked (frame counts, sizes, files), never today's numbers,
//! except that a figure's curves stay inside its panels.

mod common;

use common::{assert_error, ok, simulated, vrw};

use std::fs;
use std::path::Path;

use plotters::prelude::{BitMapBackend, IntoDrawingArea};
use vrw::output::animate::{plan_frames, AnimateOptions};
use vrw::output::read::read_run;
use vrw::output::run_plot::{draw_run_figure, RUN_SIZE};
use vrw::output::steps_plot::STEPS_SIZE;
use vrw::output::style::{png_size, COLOR_BLUE, COLOR_VERMILLION};

/// Frames of a GIF and the sum of their delays \[1/100 s\].
fn decode_gif(path: &Path) -> (usize, u64, (u16, u16)) {
    let file = fs::File::open(path).expect("walk.gif exists");
    let mut options = gif::DecodeOptions::new();
    options.set_color_output(gif::ColorOutput::Indexed);
    let mut decoder = options.read_info(file).expect("walk.gif is a GIF");
    let size = (decoder.width(), decoder.height());
    let (mut frames, mut delay) = (0, 0u64);
    while let Some(frame) = decoder.read_next_frame().expect("every frame decodes") {
        frames += 1;
        delay += u64::from(frame.delay);
    }
    (frames, delay, size)
}

fn assert_png(path: &Path, size: (u32, u32)) {
    let bytes = fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert_eq!(png_size(&bytes), Some(size), "{}", path.display());
}

fn assert_svg(path: &Path) {
    let text = fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert!(text.starts_with("<svg"), "{} is not an SVG", path.display());
}

#[test]
fn animate_writes_a_gif_with_the_planned_frames() {
    let (tmp, sim) = simulated("2");
    let dir = sim.to_str().unwrap();
    // A low frame rate, so that short phases (a slide of a few hundredths of a second) fall between
    // regular frames and must be added in slow motion.
    let stdout = ok(&vrw(
        &[
            "animate", dir, "--fps", "5", "--width", "320", "--height", "200",
        ],
        tmp.path(),
    ));
    assert!(stdout.contains("walk.gif"), "{stdout}");
    let run = read_run(&sim).unwrap();
    let plan = plan_frames(&run.samples, run.time_span(), 5, 1.0);
    let (frames, delay, size) = decode_gif(&sim.join("walk.gif"));
    assert_eq!(frames, plan.len());
    assert_eq!(size, (320, 200));
    assert_eq!(
        delay,
        20 * frames as u64,
        "5 frames/s is 20/100 s per frame"
    );
    // Every phase of the run (every interval between changes of the contacts, slides, stoppers or leg
    // indices) shows in at least one frame.
    let samples = &run.samples;
    let mut k = 0;
    while k < samples.len() {
        let mode = samples[k].mode();
        let e = k + samples[k..].iter().take_while(|s| s.mode() == mode).count();
        let (a, b) = (
            samples[k].time,
            samples.get(e).map_or(f64::INFINITY, |s| s.time),
        );
        assert!(
            plan.iter()
                .any(|f| a <= f.time && f.time < b.max(a + f64::MIN_POSITIVE)),
            "the phase {} at [{a}, {b}) s has no frame",
            samples[k].phase_name()
        );
        k = e;
    }
}

#[test]
fn animate_window_and_speed_set_the_frame_count() {
    // Two steps last well over the 1 s the window needs.
    let (tmp, sim) = simulated("2");
    let dir = sim.to_str().unwrap();
    ok(&vrw(
        &[
            "animate",
            dir,
            "--from",
            "0.5",
            "--to",
            "1.0",
            "--speed",
            "0.5",
            "--horizontal",
        ],
        tmp.path(),
    ));
    let run = read_run(&sim).unwrap();
    let opts = AnimateOptions::default();
    let plan = plan_frames(&run.samples, (0.5, 1.0), opts.fps, 0.5);
    // 0.5 s of motion at half speed and 25 frames/s: 25 regular frames plus the last instant.
    assert!(
        run.time_span().1 > 1.0,
        "the run is too short for the window"
    );
    assert_eq!(plan.iter().filter(|f| f.slow.is_none()).count(), 26);
    let (frames, _, size) = decode_gif(&sim.join("walk.gif"));
    assert_eq!(frames, plan.len());
    assert_eq!(size, (opts.width as u16, opts.height as u16));
}

#[test]
fn still_frame_is_a_png_of_the_frame_size() {
    let (tmp, sim) = simulated("1");
    ok(&vrw(
        &["animate", sim.to_str().unwrap(), "--still", "0.7"],
        tmp.path(),
    ));
    let opts = AnimateOptions::default();
    assert_png(&sim.join("walk-frame.png"), (opts.width, opts.height));
}

#[test]
fn plot_writes_run_and_steps_figures() {
    let (tmp, sim) = simulated("3");
    ok(&vrw(&["plot", sim.to_str().unwrap()], tmp.path()));
    assert_png(&sim.join("run.png"), RUN_SIZE);
    assert_png(&sim.join("steps.png"), STEPS_SIZE);
    assert_svg(&sim.join("run.svg"));
    assert_svg(&sim.join("steps.svg"));
}

/// The README's first walk (20 steps) has forces that jump at contact events; plotters joined such a jump and
/// the one-pixel step back after it with a spike that crossed the panels below (t = 16.28 s and 31.35 s).
/// No pixel of the panels' columns outside their plotting areas (2 px of frame allowed) has a curve colour.
#[test]
fn run_figure_lines_stay_inside_their_panels() {
    let (_tmp, sim) = simulated("20");
    let run = read_run(&sim).expect("the run reads back");
    let (w, h) = RUN_SIZE;
    let mut buf = vec![0u8; (w * h * 3) as usize];
    let rects = {
        let root = BitMapBackend::with_buffer(&mut buf, RUN_SIZE).into_drawing_area();
        let rects = draw_run_figure(&run, &root).expect("the run figure draws");
        root.present().expect("the bitmap is complete");
        rects
    };
    assert_eq!(rects.len(), 5, "five panels");
    let inside = |x: i32, y: i32| {
        rects.iter().any(|(px, py)| {
            (px.start - 2..px.end + 2).contains(&x) && (py.start - 2..py.end + 2).contains(&y)
        })
    };
    let colours = [COLOR_BLUE, COLOR_VERMILLION].map(|c| [c.0, c.1, c.2]);
    let (left, right) = (rects[0].0.start, rects[0].0.end);
    let mut stray = Vec::new();
    for y in 0..h as i32 {
        for x in left..right {
            let k = 3 * (y as usize * w as usize + x as usize);
            if !inside(x, y) && colours.contains(&[buf[k], buf[k + 1], buf[k + 2]]) {
                stray.push((x, y));
            }
        }
    }
    assert!(
        stray.is_empty(),
        "{} curve pixels outside the panels, e.g. {:?}",
        stray.len(),
        &stray[..stray.len().min(5)]
    );
}

#[test]
fn gait_directory_can_be_plotted_and_animated() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("gait");
    let dir = out.to_str().unwrap();
    ok(&vrw(&["gait", "--out", dir], tmp.path()));
    for file in ["gait.json", "steps.csv", "trajectory.csv", "summary.json"] {
        assert!(out.join(file).is_file(), "gait wrote no {file}");
    }
    let run = read_run(&out).unwrap();
    assert_eq!(run.steps.len(), 1, "one period of the gait");
    ok(&vrw(&["plot", dir], tmp.path()));
    assert_png(&out.join("run.png"), RUN_SIZE);
    assert_png(&out.join("steps.png"), STEPS_SIZE);
    ok(&vrw(&["animate", dir], tmp.path()));
    let opts = AnimateOptions::default();
    let plan = plan_frames(&run.samples, run.time_span(), opts.fps, opts.speed);
    assert_eq!(decode_gif(&out.join("walk.gif")).0, plan.len());
}

#[test]
fn directory_without_trajectory_is_rejected_by_name() {
    let (tmp, sim) = simulated("1");
    fs::remove_file(sim.join("trajectory.csv")).unwrap();
    let dir = sim.to_str().unwrap();
    assert_error(
        &vrw(&["animate", dir], tmp.path()),
        &["trajectory.csv", dir],
    );
    assert_error(&vrw(&["plot", dir], tmp.path()), &["trajectory.csv", dir]);
    assert!(!sim.join("walk.gif").exists() && !sim.join("run.png").exists());
}

#[test]
fn missing_directory_is_rejected() {
    let tmp = tempfile::tempdir().unwrap();
    assert_error(
        &vrw(&["animate", "no-such-dir"], tmp.path()),
        &["no-such-dir", "not a directory"],
    );
}

#[test]
fn from_after_to_is_rejected() {
    let (tmp, sim) = simulated("1");
    let out = vrw(
        &["animate", sim.to_str().unwrap(), "--from", "2", "--to", "1"],
        tmp.path(),
    );
    assert_error(&out, &["--from", "--to"]);
    assert!(!sim.join("walk.gif").exists());
}

#[test]
fn window_outside_the_run_is_rejected() {
    let (tmp, sim) = simulated("1");
    let out = vrw(
        &["animate", sim.to_str().unwrap(), "--from", "1000"],
        tmp.path(),
    );
    assert_error(&out, &["time window", "trajectory.csv"]);
}

#[test]
fn zero_fps_is_rejected() {
    let (tmp, sim) = simulated("1");
    let dir = sim.to_str().unwrap();
    assert_error(
        &vrw(&["animate", dir, "--fps", "0"], tmp.path()),
        &["--fps", "0"],
    );
    assert_error(
        &vrw(&["animate", dir, "--speed", "-1"], tmp.path()),
        &["--speed"],
    );
    assert_error(
        &vrw(&["animate", dir, "--width", "10"], tmp.path()),
        &["--width"],
    );
}

#[test]
fn extra_columns_are_ignored_and_missing_ones_named() {
    let (tmp, sim) = simulated("1");
    // A newer vrw may add columns: append one to every row of both tables.
    for name in ["steps.csv", "trajectory.csv"] {
        let path = sim.join(name);
        let text = fs::read_to_string(&path).unwrap();
        let widened: Vec<String> = text
            .lines()
            .enumerate()
            .map(|(k, l)| format!("{l},{}", if k == 0 { "pull_force" } else { "0" }))
            .collect();
        fs::write(&path, widened.join("\n") + "\n").unwrap();
    }
    ok(&vrw(&["plot", sim.to_str().unwrap()], tmp.path()));
    // Dropping a needed column is an error naming it.
    let path = sim.join("trajectory.csv");
    let text = fs::read_to_string(&path).unwrap();
    fs::write(&path, text.replacen("lambda_4", "lambda_four", 1)).unwrap();
    assert_error(
        &vrw(&["plot", sim.to_str().unwrap()], tmp.path()),
        &["lambda_4", "trajectory.csv"],
    );
}
