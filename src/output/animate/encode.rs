//! GIF encoding: frames mapped to a fixed palette through a 15-bit lookup table, each stored as the
//! rectangle that changed since the previous frame (the "Encoding" paragraph of the module doc).

use std::io::Write;
use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;
use rayon::prelude::*;

use super::super::style::PlotError;
use super::draw::{GROUND, HATCH, INK, PALETTE_BASE};
use super::plan::FrameTime;
use super::AnimateError;

/// Frames drawn in parallel before they are written.
const RENDER_CHUNK: usize = 64;

/// `a` moved `k / 8` of the way towards `b`.
fn blend(a: RGBColor, b: RGBColor, k: i32) -> [u8; 3] {
    let mix = |u: u8, v: u8| (i32::from(u) + (i32::from(v) - i32::from(u)) * k / 8) as u8;
    [mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2)]
}

/// The fixed palette: white, each drawing colour with its blends towards white, a grey ramp, and the blends
/// of the ink and the hatching with the ground (text and lines drawn on the ground).
fn palette() -> Vec<[u8; 3]> {
    let mut colors: Vec<[u8; 3]> = vec![[255, 255, 255]];
    for base in PALETTE_BASE {
        colors.extend((0..4).map(|k| blend(base, WHITE, 2 * k)));
    }
    colors.extend((0..12).map(|k| {
        let g = (k * 255 / 11) as u8;
        [g, g, g]
    }));
    for base in [INK, HATCH] {
        colors.extend((1..4).map(|k| blend(base, GROUND, 2 * k)));
    }
    colors.truncate(63);
    colors
}

/// A 15-bit RGB to palette index lookup table (nearest colour in RGB distance).
fn lookup(palette: &[[u8; 3]]) -> Vec<u8> {
    let mut lut = vec![0u8; 1 << 15];
    for (key, slot) in lut.iter_mut().enumerate() {
        let c = [
            ((key >> 10) & 31) as i32 * 8 + 4,
            ((key >> 5) & 31) as i32 * 8 + 4,
            (key & 31) as i32 * 8 + 4,
        ];
        let mut best = (i32::MAX, 0usize);
        for (i, p) in palette.iter().enumerate() {
            let d: i32 = (0..3).map(|j| (c[j] - i32::from(p[j])).pow(2)).sum();
            if d < best.0 {
                best = (d, i);
            }
        }
        *slot = best.1 as u8;
    }
    lut
}

/// Hundredths of a second from the start of playback to frame `k` at `fps` frames per second (GIF delays are
/// whole hundredths).
pub(super) fn centis(k: usize, fps: u32) -> u64 {
    (k as f64 * 100.0 / f64::from(fps)).round() as u64
}

/// A writer that counts the bytes it passes on.
struct Counted<W> {
    inner: W,
    bytes: u64,
}

impl<W: Write> Write for Counted<W> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let n = self.inner.write(buf)?;
        self.bytes += n as u64;
        Ok(n)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.inner.flush()
    }
}

/// Draws `frames` with `draw` and writes them to `out` (errors name `path`, the file being made) as a looping
/// GIF of `width` x `height` pixels played at `fps` frames per second; returns the size of the GIF \[bytes\].
///
/// Frames are drawn, mapped to the palette and LZW-compressed in parallel, a chunk at a time, and written in
/// order.
pub(super) fn write_gif(
    out: impl Write,
    path: &Path,
    (width, height): (u32, u32),
    fps: u32,
    frames: &[FrameTime],
    draw: impl Fn(&DrawingArea<BitMapBackend<'_>, Shift>, &FrameTime) -> Result<(), PlotError> + Sync,
) -> Result<u64, AnimateError> {
    let write_err = |message: String| AnimateError::Write {
        path: path.to_path_buf(),
        message,
    };
    let palette = palette();
    let lut = lookup(&palette);
    let transparent = palette.len() as u8;
    let mut flat: Vec<u8> = palette.iter().flatten().copied().collect();
    flat.extend([255, 0, 255]);
    let (w, h) = (width as usize, height as usize);
    let format = FrameFormat {
        w,
        h,
        transparent,
        fps,
    };
    let out = Counted {
        inner: out,
        bytes: 0,
    };
    let mut encoder =
        gif::Encoder::new(out, w as u16, h as u16, &flat).map_err(|e| write_err(e.to_string()))?;
    encoder
        .set_repeat(gif::Repeat::Infinite)
        .map_err(|e| write_err(e.to_string()))?;

    let mut previous: Option<Vec<u8>> = None;
    for (c, chunk) in frames.chunks(RENDER_CHUNK).enumerate() {
        // A chunk takes well under a second to draw: Ctrl-C is answered between two.
        if crate::walk::interrupted() {
            return Err(AnimateError::Interrupted {
                frames: c * RENDER_CHUNK,
                total: frames.len(),
            });
        }
        let indexed = render_indexed(chunk, (width, height), &lut, &draw)?;
        let encoded = encode_chunk(&indexed, previous.as_deref(), c * RENDER_CHUNK, &format);
        for frame in &encoded {
            encoder
                .write_lzw_pre_encoded_frame(frame)
                .map_err(|e| write_err(e.to_string()))?;
        }
        previous = indexed.into_iter().last();
    }
    let mut out = encoder.into_inner().map_err(|e| write_err(e.to_string()))?;
    out.flush().map_err(|e| write_err(e.to_string()))?;
    Ok(out.bytes)
}

/// What every frame of a GIF shares: its size \[px\], the palette's transparent index and the frame rate.
struct FrameFormat {
    /// Width \[px\].
    w: usize,
    /// Height \[px\].
    h: usize,
    /// The palette index of unchanged pixels.
    transparent: u8,
    /// Frames per second.
    fps: u32,
}

/// Draws the frames of `chunk` with `draw` at `width` x `height` pixels in parallel and maps each to palette
/// indices through the lookup table `lut`.
fn render_indexed(
    chunk: &[FrameTime],
    (width, height): (u32, u32),
    lut: &[u8],
    draw: &(impl Fn(&DrawingArea<BitMapBackend<'_>, Shift>, &FrameTime) -> Result<(), PlotError> + Sync),
) -> Result<Vec<Vec<u8>>, PlotError> {
    let (w, h) = (width as usize, height as usize);
    chunk
        .par_iter()
        .map_init(
            || vec![255u8; w * h * 3],
            |rgb, frame| {
                {
                    let root = BitMapBackend::with_buffer(rgb, (width, height)).into_drawing_area();
                    draw(&root, frame)?;
                }
                Ok(rgb
                    .chunks_exact(3)
                    .map(|px| {
                        lut[(usize::from(px[0] >> 3) << 10)
                            | (usize::from(px[1] >> 3) << 5)
                            | usize::from(px[2] >> 3)]
                    })
                    .collect())
            },
        )
        .collect::<Result<_, PlotError>>()
}

/// The GIF frames of the indexed frames `indexed`, the first of which is frame `first` of the animation
/// (`previous`: the frame before it), each LZW-compressed, in parallel.
fn encode_chunk(
    indexed: &[Vec<u8>],
    previous: Option<&[u8]>,
    first: usize,
    format: &FrameFormat,
) -> Vec<gif::Frame<'static>> {
    let FrameFormat {
        w,
        h,
        transparent,
        fps,
    } = *format;
    (0..indexed.len())
        .into_par_iter()
        .map(|i| {
            let k = first + i;
            let before = if i == 0 {
                previous
            } else {
                Some(indexed[i - 1].as_slice())
            };
            let delay = (centis(k + 1, fps) - centis(k, fps)) as u16;
            let mut frame = changed_rect(before, &indexed[i], w, h, transparent, delay);
            frame.make_lzw_pre_encoded();
            frame
        })
        .collect()
}

/// The GIF frame for `current`: the whole frame first, then only the rectangle that changed since `previous`,
/// its unchanged pixels transparent.
fn changed_rect(
    previous: Option<&[u8]>,
    current: &[u8],
    w: usize,
    h: usize,
    transparent: u8,
    delay: u16,
) -> gif::Frame<'static> {
    let mut frame = match previous {
        None => gif::Frame::from_indexed_pixels(w as u16, h as u16, current.to_vec(), None),
        Some(prev) => {
            let (mut x0, mut y0, mut x1, mut y1) = (w, h, 0, 0);
            for y in 0..h {
                let row = y * w..(y + 1) * w;
                let (a, b) = (&prev[row.clone()], &current[row]);
                if a == b {
                    continue;
                }
                let first = a.iter().zip(b).position(|(u, v)| u != v).unwrap_or(0);
                let last = w
                    - 1
                    - a.iter()
                        .rev()
                        .zip(b.iter().rev())
                        .position(|(u, v)| u != v)
                        .unwrap_or(0);
                x0 = x0.min(first);
                x1 = x1.max(last);
                y0 = y0.min(y);
                y1 = y1.max(y);
            }
            if x0 > x1 {
                (x0, y0, x1, y1) = (0, 0, 0, 0);
            }
            let (fw, fh) = (x1 - x0 + 1, y1 - y0 + 1);
            let mut buffer = Vec::with_capacity(fw * fh);
            for y in y0..=y1 {
                for x in x0..=x1 {
                    let i = y * w + x;
                    buffer.push(if prev[i] == current[i] {
                        transparent
                    } else {
                        current[i]
                    });
                }
            }
            let mut f =
                gif::Frame::from_indexed_pixels(fw as u16, fh as u16, buffer, Some(transparent));
            f.left = x0 as u16;
            f.top = y0 as u16;
            f
        }
    };
    frame.delay = delay;
    frame.dispose = gif::DisposalMethod::Keep;
    frame
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn palette_fits_a_gif_with_its_transparent_index() {
        let p = palette();
        assert!(p.len() < 256);
        let lut = lookup(&p);
        assert_eq!(lut[(31 << 10) | (31 << 5) | 31], 0, "white maps to white");
    }
}
