//! Styling shared by every figure (STYLE.md point 16): the bundled font, text styles (with rich text: the
//! subscripts and superscripts of Fig. 2's labels), tick labels, the colour palette and the figure error
//! type.
//!
//! Text is rendered with DejaVu Sans, bundled under `assets/fonts/` (license next to it) and registered with
//! plotters' `ab_glyph` font table, so no system font or font library is needed at run time. PNGs and GIF
//! frames are rasterised with that font; SVGs keep their text as `<text>` elements with
//! `font-family="DejaVu Sans, sans-serif"`.

use std::ops::Range;
use std::path::Path;
use std::sync::OnceLock;

use plotters::chart::MeshStyle;
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::{register_font, FontStyle, FontTransform};

/// Why a figure could not be written.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// The backend failed to draw or to write the file at `path`.
    #[error("cannot draw {path}: {message}")]
    Draw {
        /// The file.
        path: String,
        /// What went wrong.
        message: String,
    },
    /// Nothing finite to plot.
    #[error("no data to plot: {0}")]
    Empty(String),
}

impl From<super::OutputError> for PlotError {
    fn from(e: super::OutputError) -> PlotError {
        let path = match &e {
            super::OutputError::Io { path, .. }
            | super::OutputError::Csv { path, .. }
            | super::OutputError::Json { path, .. }
            | super::OutputError::NotADirectory { path } => path.display().to_string(),
            super::OutputError::NotVrwDir { dir, .. }
            | super::OutputError::OtherRun { dir, .. } => dir.display().to_string(),
        };
        PlotError::Draw {
            path,
            message: e.to_string(),
        }
    }
}

impl PlotError {
    /// The same error, naming the file `to` where it named its temporary file `from`.
    pub(crate) fn renamed(self, from: &Path, to: &Path) -> PlotError {
        match self {
            PlotError::Draw { path, message } if path == from.display().to_string() => {
                PlotError::Draw {
                    path: to.display().to_string(),
                    message,
                }
            }
            other => other,
        }
    }

    /// A drawing failure at `path` (for `map_err`).
    pub(crate) fn draw_at(path: &Path) -> impl Fn(String) -> PlotError + '_ {
        move |message| PlotError::Draw {
            path: path.display().to_string(),
            message,
        }
    }
}

/// Font family name under which the bundled font is registered; it is also the CSS `font-family` list
/// written into SVGs.
pub(crate) const FAMILY: &str = "DejaVu Sans, sans-serif";
static FONT_BYTES: &[u8] = include_bytes!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/assets/fonts/DejaVuSans.ttf"
));
static FONT_REGISTERED: OnceLock<bool> = OnceLock::new();

/// Registers the bundled DejaVu Sans once per process, under [`FAMILY`] and under plotters' default
/// `"sans-serif"`. Returns whether it succeeded.
pub(crate) fn ensure_font() -> bool {
    *FONT_REGISTERED.get_or_init(|| {
        register_font(FAMILY, FontStyle::Normal, FONT_BYTES).is_ok()
            && register_font("sans-serif", FontStyle::Normal, FONT_BYTES).is_ok()
    })
}

/// Registers the bundled font, or fails naming the file that was to be drawn.
pub(crate) fn require_font(path: &Path) -> Result<(), PlotError> {
    if ensure_font() {
        Ok(())
    } else {
        Err(PlotError::draw_at(path)(
            "the bundled DejaVu Sans font is invalid".into(),
        ))
    }
}

/// Black text in the bundled font at `size` pixels.
pub(crate) fn font(size: f64) -> TextStyle<'static> {
    (FontFamily::Name(FAMILY), size).into_font().color(&BLACK)
}

/// A run of rich text: text on the baseline, a subscript, or a stacked subscript/superscript pair (plotters
/// has no rich text).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Seg {
    /// Text on the baseline.
    Text(&'static str),
    /// A subscript.
    Sub(&'static str),
    /// A subscript with a superscript above it.
    SubSup(&'static str, &'static str),
}

/// Sizes of a subscript relative to its base text, and the baseline shifts.
const SUB_SCALE: f64 = 0.68;
const SUB_DROP: f64 = 0.16;
const SUP_RISE: f64 = 0.36;

/// Width in pixels of rich text at font size `size`.
pub(crate) fn rich_width<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    segs: &[Seg],
    size: f64,
) -> Result<i32, DrawingAreaErrorKind<DB::ErrorType>> {
    let w = |t: &str, sz: f64| root.estimate_text_size(t, &font(sz)).map(|s| s.0 as i32);
    let mut total = 0;
    for seg in segs {
        total += match *seg {
            Seg::Text(t) => w(t, size)?,
            Seg::Sub(t) => w(t, size * SUB_SCALE)? + 2,
            Seg::SubSup(a, b) => w(a, size * SUB_SCALE)?.max(w(b, size * SUB_SCALE)?) + 2,
        };
    }
    Ok(total)
}

/// Draws rich text whose first line box has its top-left corner at `at`
/// (with `rotated`, the text runs upwards from `at`, its top facing left).
/// Baselines follow plotters' ab_glyph rasteriser: `size / 2` below the top.
pub(crate) fn draw_rich<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    segs: &[Seg],
    at: (i32, i32),
    size: f64,
    rotated: bool,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let small = size * SUB_SCALE;
    let base = size / 2.0;
    let mut advance = 0;
    let put = |t: &str, sz: f64, baseline: f64, advance: i32| {
        let down = (baseline - sz / 2.0).round() as i32;
        let (pos, style) = if rotated {
            (
                (at.0 + down, at.1 - advance),
                font(sz).transform(FontTransform::Rotate270),
            )
        } else {
            ((at.0 + advance, at.1 + down), font(sz))
        };
        root.draw(&Text::new(t.to_string(), pos, style))
    };
    for seg in segs {
        match *seg {
            Seg::Text(t) => {
                // SVG drops leading blanks of a <text>: advance past them instead.
                let body = t.trim_start();
                let lead = rich_width(root, &[Seg::Text(t)], size)?
                    - rich_width(root, &[Seg::Text(body)], size)?;
                put(body, size, base, advance + lead)?
            }
            Seg::Sub(t) => put(t, small, base + SUB_DROP * size, advance + 1)?,
            Seg::SubSup(a, b) => {
                put(a, small, base + SUB_DROP * size, advance + 1)?;
                put(b, small, base - SUP_RISE * size, advance + 1)?;
            }
        }
        advance += rich_width(root, &[*seg], size)?;
    }
    Ok(())
}

/// Black (Fig. 2's `lambda_I4`, the first series of a panel).
pub(crate) const COLOR_BLACK: RGBColor = RGBColor(0, 0, 0);
/// Blue (Okabe-Ito): Leg 1, `lambda_2`.
pub const COLOR_BLUE: RGBColor = RGBColor(0, 114, 178);
/// Vermillion (Okabe-Ito): Leg 2, `lambda_4`.
pub const COLOR_VERMILLION: RGBColor = RGBColor(213, 94, 0);
/// Bluish green (Okabe-Ito).
pub(crate) const COLOR_GREEN: RGBColor = RGBColor(0, 158, 115);
/// Reddish purple (Okabe-Ito).
pub(crate) const COLOR_PURPLE: RGBColor = RGBColor(204, 121, 167);
/// Orange (Okabe-Ito).
pub(crate) const COLOR_ORANGE: RGBColor = RGBColor(230, 159, 0);
/// Grey of markers and reference lines.
pub(crate) const COLOR_MARK: RGBColor = RGBColor(90, 90, 90);
/// Grid lines.
pub(crate) const COLOR_GRID: RGBColor = RGBColor(225, 225, 225);
/// Border of legend boxes and colour swatches.
pub(crate) const COLOR_FRAME: RGBColor = RGBColor(150, 150, 150);

/// Applies the house style to a chart's mesh: fonts, light grid, black axes, tick marks.
pub(crate) fn house_mesh<DB: DrawingBackend>(
    mesh: &mut MeshStyle<'_, '_, RangedCoordf64, RangedCoordf64, DB>,
    tick_font: f64,
    axis_font: f64,
) {
    mesh.label_style(font(tick_font))
        .axis_desc_style(font(axis_font))
        .bold_line_style(COLOR_GRID.stroke_width(1))
        .light_line_style(TRANSPARENT)
        .axis_style(BLACK.stroke_width(2))
        .set_all_tick_mark_size(8);
}

/// Proportions of a legend box \[px\]: rows of a sample (line, marker or swatch) and a text.
#[derive(Debug, Clone, Copy)]
pub(crate) struct LegendLayout {
    /// Padding left and right inside the box.
    pub pad: i32,
    /// Width of a sample.
    pub sample_w: i32,
    /// Gap between sample and text.
    pub gap: i32,
    /// Height of a row.
    pub line: i32,
    /// Padding above the first row.
    pub top: i32,
}

impl LegendLayout {
    /// A layout from its padding, sample width, gap, row height and top padding \[px\].
    pub(crate) const fn new(
        pad: i32,
        sample_w: i32,
        gap: i32,
        line: i32,
        top: i32,
    ) -> LegendLayout {
        LegendLayout {
            pad,
            sample_w,
            gap,
            line,
            top,
        }
    }

    /// Draws the white framed box of `rows` rows whose widest text is `text_w` at `(x0, y0)`; returns the x of
    /// the samples, the x of the texts and the centre y of the first row.
    pub(crate) fn frame<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        (x0, y0): (i32, i32),
        rows: usize,
        text_w: i32,
    ) -> Result<(i32, i32, i32), DrawingAreaErrorKind<DB::ErrorType>> {
        let box_w = 2 * self.pad + self.sample_w + self.gap + text_w;
        let box_h = rows as i32 * self.line + 2 * self.top;
        draw_box(root, [(x0, y0), (x0 + box_w, y0 + box_h)], WHITE)?;
        let sx = x0 + self.pad;
        Ok((
            sx,
            sx + self.sample_w + self.gap,
            y0 + self.top + self.line / 2,
        ))
    }
}

/// Draws the rectangle `corners` filled with `fill` and framed in [`COLOR_FRAME`] (legend boxes, swatches).
pub(crate) fn draw_box<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    corners: [(i32, i32); 2],
    fill: RGBColor,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    root.draw(&Rectangle::new(corners, fill.filled()))?;
    root.draw(&Rectangle::new(corners, COLOR_FRAME.stroke_width(1)))
}

/// Tick label of `v` on an axis spanning `range`: as many decimals as the tick step needs (plotters' default
/// prints "100.0"), scientific notation on a very narrow or very wide axis, and a true minus sign.
pub(crate) fn tick_label(v: f64, range: &Range<f64>) -> String {
    let span = (range.end - range.start).abs().max(f64::MIN_POSITIVE);
    // Smallest 1-2-5 step giving at most 10 ticks (plotters asks for <= 10).
    let mut step = 10f64.powf((span / 10.0).log10().floor());
    for m in [1.0, 2.0, 5.0, 10.0] {
        if span / (m * step) <= 10.0 {
            step *= m;
            break;
        }
    }
    if !(1e-4..1e6).contains(&step) {
        if v.abs() < 1e-3 * step {
            return "0".to_string();
        }
        return format!("{v:.1e}").replace('-', "\u{2212}");
    }
    let mut decimals = (-step.log10().floor()).max(0.0) as usize;
    let mut s = format!("{v:.decimals$}");
    while decimals < 8 && (s.parse::<f64>().unwrap_or(v) - v).abs() > 1e-6 * step {
        decimals += 1;
        s = format!("{v:.decimals$}");
    }
    if s.parse::<f64>() == Ok(0.0) {
        return format!("{:.decimals$}", 0.0);
    }
    s.replace('-', "\u{2212}")
}

/// `(lo, hi)` widened by `frac` of its span on both sides (a unit span around a single value).
pub(crate) fn padded(lo: f64, hi: f64, frac: f64) -> Range<f64> {
    let span = if hi > lo { hi - lo } else { lo.abs().max(1.0) };
    (lo - frac * span)..(hi + frac * span)
}

/// Size in pixels of a PNG from its header (`None` if `bytes` is not a PNG).
pub fn png_size(bytes: &[u8]) -> Option<(u32, u32)> {
    if bytes.len() < 24 || &bytes[..8] != b"\x89PNG\r\n\x1a\n" || &bytes[12..16] != b"IHDR" {
        return None;
    }
    let be = |s: &[u8]| u32::from_be_bytes([s[0], s[1], s[2], s[3]]);
    Some((be(&bytes[16..20]), be(&bytes[20..24])))
}

/// Encode an RGB bitmap of `size` pixels as the PNG file `path`, with the encoder plotters uses (the same
/// bytes as its `BitMapBackend::new(path, ..)`), but encoded in memory and written with `std::fs::write`: a
/// failed write (a full disk) is an error that says what happened (`No space left on device`), where plotters
/// prints debug text, and it is never lost in a buffered writer's drop.
pub(crate) fn save_png(path: &Path, rgb: &[u8], size: (u32, u32)) -> Result<(), PlotError> {
    let bytes = png_bytes(path, rgb, size)?;
    std::fs::write(path, bytes).map_err(|e| PlotError::Draw {
        path: path.display().to_string(),
        message: e.to_string(),
    })
}

/// The bytes [`save_png`] writes (errors name `path`, the file being made).
pub(crate) fn png_bytes(path: &Path, rgb: &[u8], size: (u32, u32)) -> Result<Vec<u8>, PlotError> {
    use image::ImageEncoder;
    let mut bytes = Vec::new();
    image::codecs::png::PngEncoder::new(&mut bytes)
        .write_image(rgb, size.0, size.1, image::ColorType::Rgb8)
        .map_err(|e| PlotError::Draw {
            path: path.display().to_string(),
            message: e.to_string(),
        })?;
    Ok(bytes)
}

impl PlotError {
    /// The same error, naming `path` (the file the user asked for, not its temporary name).
    pub(crate) fn at(self, path: &Path) -> PlotError {
        match self {
            PlotError::Draw { message, .. } => PlotError::Draw {
                path: path.display().to_string(),
                message,
            },
            other => other,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A full disk is reported as the OS says it, not as plotters' debug text
    /// (`ImageError(IoError(Custom {...}))`).
    #[test]
    fn full_disk_error_is_readable() {
        let full = Path::new("/dev/full");
        if !full.exists() {
            return; // not a Linux machine
        }
        let e = save_png(full, &[255; 3 * 4 * 4], (4, 4))
            .unwrap_err()
            .to_string();
        assert!(e.contains("No space left on device"), "{e}");
        assert!(!e.contains("Custom") && !e.contains("IoError"), "{e}");
    }
}
