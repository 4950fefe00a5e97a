//! A minimal SVG writer: elements appended to a string, numbers with two decimals, text
//! escaped. No DOM, no dependencies; the caller keeps groups balanced ([`Doc::open`] /
//! [`Doc::close`], checked by a debug assertion in [`Doc::finish`]).

use std::fmt::Write;

/// An SVG document being written.
#[derive(Debug)]
pub(crate) struct Doc {
    out: String,
    depth: usize,
}

/// A number as SVG wants it: at most two decimals, no trailing zeros, no `-0`.
pub(crate) fn num(x: f64) -> String {
    if !x.is_finite() {
        return "0".into();
    }
    kerf_io::decimal(x, 2)
}

/// Escapes `&`, `<`, `>`, `"` and `'` for text content and attribute values.
pub(crate) fn esc(text: &str) -> String {
    let mut s = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => s.push_str("&amp;"),
            '<' => s.push_str("&lt;"),
            '>' => s.push_str("&gt;"),
            '"' => s.push_str("&quot;"),
            '\'' => s.push_str("&apos;"),
            // Control characters are not allowed in XML 1.0.
            c if (c as u32) < 0x20 && c != '\n' && c != '\t' => s.push('?'),
            c => s.push(c),
        }
    }
    s
}

impl Doc {
    /// Starts a document of `width` x `height` pixels with the given stylesheet.
    pub(crate) fn new(width: f64, height: f64, title: &str, style: &str) -> Self {
        let mut out = String::with_capacity(1 << 16);
        let _ = write!(
            out,
            "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n\
             <svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" \
             viewBox=\"0 0 {w} {h}\" font-family=\"Helvetica, Arial, sans-serif\">\n\
             <title>{t}</title>\n<style>{style}</style>\n\
             <rect width=\"100%\" height=\"100%\" fill=\"#ffffff\"/>\n",
            w = num(width),
            h = num(height),
            t = esc(title),
        );
        Doc { out, depth: 0 }
    }

    /// Appends raw markup (already escaped).
    pub(crate) fn raw(&mut self, markup: &str) {
        self.out.push_str(markup);
    }

    /// Opens `<g>` with the given attributes (`id="..." class="..."`, already escaped).
    pub(crate) fn open(&mut self, attrs: &str) {
        self.depth += 1;
        if attrs.is_empty() {
            self.out.push_str("<g>\n");
        } else {
            let _ = writeln!(self.out, "<g {attrs}>");
        }
    }

    /// Closes the innermost `<g>`.
    pub(crate) fn close(&mut self) {
        self.depth = self.depth.saturating_sub(1);
        self.out.push_str("</g>\n");
    }

    /// A line.
    pub(crate) fn line(&mut self, x1: f64, y1: f64, x2: f64, y2: f64, attrs: &str) {
        let _ = writeln!(
            self.out,
            "<line x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\" {attrs}/>",
            num(x1),
            num(y1),
            num(x2),
            num(y2)
        );
    }

    /// A polyline through `points` (nothing for fewer than two points).
    pub(crate) fn polyline(&mut self, points: &[(f64, f64)], attrs: &str) {
        if points.len() < 2 {
            return;
        }
        self.out.push_str("<polyline points=\"");
        for (i, (x, y)) in points.iter().enumerate() {
            if i > 0 {
                self.out.push(' ');
            }
            let _ = write!(self.out, "{},{}", num(*x), num(*y));
        }
        let _ = writeln!(self.out, "\" fill=\"none\" {attrs}/>");
    }

    /// A circle.
    pub(crate) fn circle(&mut self, cx: f64, cy: f64, r: f64, attrs: &str) {
        let _ = writeln!(
            self.out,
            "<circle cx=\"{}\" cy=\"{}\" r=\"{}\" {attrs}/>",
            num(cx),
            num(cy),
            num(r)
        );
    }

    /// An empty panel: the frame with `note` in its middle, and the panel's `<g>` closed.
    pub(crate) fn empty_panel(&mut self, frame: crate::layout::Rect, note: &str) {
        self.rect(frame.x, frame.y, frame.w, frame.h, "class=\"frame\"");
        self.text(
            frame.x + frame.w / 2.0,
            frame.y + frame.h / 2.0,
            note,
            "class=\"note\" text-anchor=\"middle\"",
        );
        self.close();
    }

    /// A rectangle.
    pub(crate) fn rect(&mut self, x: f64, y: f64, w: f64, h: f64, attrs: &str) {
        let _ = writeln!(
            self.out,
            "<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" {attrs}/>",
            num(x),
            num(y),
            num(w.max(0.0)),
            num(h.max(0.0))
        );
    }

    /// Text at `(x, y)` (the baseline), escaped.
    pub(crate) fn text(&mut self, x: f64, y: f64, content: &str, attrs: &str) {
        let _ = writeln!(
            self.out,
            "<text x=\"{}\" y=\"{}\" {attrs}>{}</text>",
            num(x),
            num(y),
            esc(content)
        );
    }

    /// Text rotated by -90 degrees about `(x, y)` (reads bottom to top), centred there.
    pub(crate) fn vtext(&mut self, x: f64, y: f64, content: &str, attrs: &str) {
        let _ = writeln!(
            self.out,
            "<text x=\"{x}\" y=\"{y}\" transform=\"rotate(-90 {x} {y})\" text-anchor=\"middle\" {attrs}>{}</text>",
            esc(content),
            x = num(x),
            y = num(y),
        );
    }

    /// Ends the document and returns its text.
    pub(crate) fn finish(mut self) -> String {
        debug_assert_eq!(self.depth, 0, "every <g> closed");
        self.out.push_str("</svg>\n");
        self.out
    }
}

/// A rough width in pixels of `text` at `font_size` (for layout decisions only).
pub(crate) fn text_width(text: &str, font_size: f64) -> f64 {
    text.chars().count() as f64 * font_size * 0.56
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_short() {
        assert_eq!(num(1.0), "1", "integers");
        assert_eq!(num(1.234_567), "1.23", "two decimals");
        assert_eq!(num(-0.001), "0", "no negative zero");
        assert_eq!(num(f64::NAN), "0", "never NaN in the markup");
        assert_eq!(num(12.5), "12.5", "trailing zero trimmed");
    }

    #[test]
    fn text_is_escaped() {
        assert_eq!(esc("a<b & \"c\""), "a&lt;b &amp; &quot;c&quot;", "escaped");
        let mut d = Doc::new(10.0, 10.0, "t<", "");
        d.open("id=\"g\"");
        d.text(1.0, 2.0, "<x>", "");
        d.close();
        let s = d.finish();
        assert!(s.contains("<title>t&lt;</title>"), "{s}");
        assert!(s.contains(">&lt;x&gt;</text>"), "{s}");
    }
}
