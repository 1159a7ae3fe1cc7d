//! A 3×5 pixel bitmap font (upper case, digits, a little punctuation) for the overlay:
//! enough for numbers and short labels without a font dependency.

/// Glyph width and height in font pixels; glyphs advance by `GLYPH_W + 1`.
pub const GLYPH_W: usize = 3;
/// Glyph height in font pixels; lines advance by `GLYPH_H + 2`.
pub const GLYPH_H: usize = 5;

/// Rows of a glyph, top first; bit 2 is the left column. Lower case maps to upper case;
/// unknown characters draw as a hollow box so they are visible, not silently dropped.
pub fn glyph(c: char) -> [u8; GLYPH_H] {
    match c.to_ascii_uppercase() {
        ' ' => [0, 0, 0, 0, 0],
        '0' => [7, 5, 5, 5, 7],
        '1' => [2, 6, 2, 2, 7],
        '2' => [7, 1, 7, 4, 7],
        '3' => [7, 1, 3, 1, 7],
        '4' => [5, 5, 7, 1, 1],
        '5' => [7, 4, 7, 1, 7],
        '6' => [7, 4, 7, 5, 7],
        '7' => [7, 1, 2, 2, 2],
        '8' => [7, 5, 7, 5, 7],
        '9' => [7, 5, 7, 1, 7],
        'A' => [2, 5, 7, 5, 5],
        'B' => [6, 5, 6, 5, 6],
        'C' => [3, 4, 4, 4, 3],
        'D' => [6, 5, 5, 5, 6],
        'E' => [7, 4, 6, 4, 7],
        'F' => [7, 4, 6, 4, 4],
        'G' => [3, 4, 5, 5, 3],
        'H' => [5, 5, 7, 5, 5],
        'I' => [7, 2, 2, 2, 7],
        'J' => [1, 1, 1, 5, 2],
        'K' => [5, 5, 6, 5, 5],
        'L' => [4, 4, 4, 4, 7],
        'M' => [5, 7, 7, 5, 5],
        'N' => [6, 5, 5, 5, 5],
        'O' => [2, 5, 5, 5, 2],
        'P' => [6, 5, 6, 4, 4],
        'Q' => [2, 5, 5, 6, 3],
        'R' => [6, 5, 6, 5, 5],
        'S' => [3, 4, 2, 1, 6],
        'T' => [7, 2, 2, 2, 2],
        'U' => [5, 5, 5, 5, 7],
        'V' => [5, 5, 5, 5, 2],
        'W' => [5, 5, 7, 7, 5],
        'X' => [5, 5, 2, 5, 5],
        'Y' => [5, 5, 2, 2, 2],
        'Z' => [7, 1, 2, 4, 7],
        '.' => [0, 0, 0, 0, 2],
        ',' => [0, 0, 0, 2, 4],
        ':' => [0, 2, 0, 2, 0],
        '-' => [0, 0, 7, 0, 0],
        '+' => [0, 2, 7, 2, 0],
        '=' => [0, 7, 0, 7, 0],
        '/' => [1, 1, 2, 4, 4],
        '(' => [1, 2, 2, 2, 1],
        ')' => [4, 2, 2, 2, 4],
        '%' => [5, 1, 2, 4, 5],
        '>' => [4, 2, 1, 2, 4],
        _ => [7, 5, 5, 5, 7],
    }
}

/// Draws `text` into a 0RGB framebuffer of `width` pixels per row at (x, y), each font
/// pixel `scale`×`scale` screen pixels, over a dark box so it reads on any background;
/// returns nothing, clips at the buffer's edges.
pub fn draw_text(buf: &mut [u32], width: usize, x: usize, y: usize, scale: usize, text: &str) {
    let height = buf.len() / width.max(1);
    let (box_w, box_h) = text_box(text, scale);
    for row in y..(y + box_h).min(height) {
        for px in &mut buf[row * width + x.min(width)..row * width + (x + box_w).min(width)] {
            *px = (*px >> 2) & 0x003f_3f3f;
        }
    }
    for (line_index, line) in text.lines().enumerate() {
        let top = y + (line_index * (GLYPH_H + 2) + 1) * scale;
        for (col, c) in line.chars().enumerate() {
            let left = x + (col * (GLYPH_W + 1) + 1) * scale;
            for (gy, bits) in glyph(c).iter().enumerate() {
                for gx in 0..GLYPH_W {
                    if bits & (4 >> gx) != 0 {
                        fill(
                            buf,
                            width,
                            height,
                            left + gx * scale,
                            top + gy * scale,
                            scale,
                        );
                    }
                }
            }
        }
    }
}

/// Width and height in pixels of the dark box [`draw_text`] draws `text` on.
pub fn text_box(text: &str, scale: usize) -> (usize, usize) {
    let cols = text.lines().map(|l| l.chars().count()).max().unwrap_or(0);
    let box_w = (cols * (GLYPH_W + 1) + 1) * scale;
    let box_h = (text.lines().count() * (GLYPH_H + 2) + 1) * scale;
    (box_w, box_h)
}

/// `text` as [`draw_text`] draws it, as a premultiplied-alpha RGBA8 image of its box
/// (width, height, texels) to blend over a frame: the glyphs opaque white, the box black
/// at alpha 3/4, which darkens what is under it to a quarter as `draw_text` does.
#[cfg(any(test, feature = "wgpu"))]
pub fn text_rgba(text: &str, scale: usize) -> (usize, usize, Vec<u8>) {
    let (w, h) = text_box(text, scale);
    let mut words = vec![0u32; w * h];
    draw_text(&mut words, w, 0, 0, scale, text);
    let texels = words
        .iter()
        .flat_map(|&p| match p {
            0 => [0, 0, 0, 191],
            p => [(p >> 16) as u8, (p >> 8) as u8, p as u8, 255],
        })
        .collect();
    (w, h, texels)
}

fn fill(buf: &mut [u32], width: usize, height: usize, x: usize, y: usize, size: usize) {
    for row in y..(y + size).min(height) {
        for col in x..(x + size).min(width) {
            buf[row * width + col] = 0x00ff_ffff;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_listed_glyph_is_distinct_and_fits_three_columns() {
        let chars = "0123456789ABCDEFGHIJKLMNOPQRSTUVWXYZ.,:-+=/()%>";
        let glyphs: Vec<_> = chars.chars().map(glyph).collect();
        for (i, g) in glyphs.iter().enumerate() {
            assert!(
                g.iter().all(|&r| r < 8),
                "{:?} is wider than 3",
                chars.chars().nth(i)
            );
            for (j, h) in glyphs[..i].iter().enumerate() {
                assert_ne!(
                    g,
                    h,
                    "{:?} and {:?} look alike",
                    chars.chars().nth(i),
                    chars.chars().nth(j)
                );
            }
        }
    }

    #[test]
    fn text_lights_exactly_the_glyph_pixels_and_clips_at_the_edge() {
        let mut buf = vec![0u32; 20 * 10];
        draw_text(&mut buf, 20, 0, 0, 1, "1");
        // '1' is [2, 6, 2, 2, 7] at (1, 1): 1 + 2 + 1 + 1 + 3 lit pixels.
        assert_eq!(buf.iter().filter(|&&p| p == 0x00ff_ffff).count(), 8);
        assert_eq!(buf[20 + 2], 0x00ff_ffff, "top of the 1's stem");
        let mut small = vec![0u32; 4 * 4];
        draw_text(&mut small, 4, 2, 2, 3, "WWW");
    }

    #[test]
    fn the_rgba_overlay_is_the_text_box_with_opaque_glyphs_over_a_dark_veil() {
        let (w, h, rgba) = text_rgba("1\n22", 2);
        assert_eq!((w, h), text_box("1\n22", 2));
        assert_eq!((w, h), ((2 * 4 + 1) * 2, (2 * 7 + 1) * 2));
        assert_eq!(rgba.len(), 4 * w * h);
        let glyph = rgba.chunks_exact(4).filter(|p| *p == [255, 255, 255, 255]);
        // '1' lights 8 font pixels, each '2' 11: 30 font pixels of 2x2.
        assert_eq!(glyph.count(), 4 * (8 + 2 * 11));
        let veil = rgba
            .chunks_exact(4)
            .filter(|p| *p == [0, 0, 0, 191])
            .count();
        assert_eq!(veil, w * h - 4 * 30, "every other texel is the veil");
    }
}
