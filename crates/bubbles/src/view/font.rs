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
    let lines: Vec<&str> = text.lines().collect();
    let cols = lines.iter().map(|l| l.chars().count()).max().unwrap_or(0);
    let box_w = (cols * (GLYPH_W + 1) + 1) * scale;
    let box_h = (lines.len() * (GLYPH_H + 2) + 1) * scale;
    for row in y..(y + box_h).min(height) {
        for px in &mut buf[row * width + x.min(width)..row * width + (x + box_w).min(width)] {
            *px = (*px >> 2) & 0x003f_3f3f;
        }
    }
    for (line_index, line) in lines.iter().enumerate() {
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
}
