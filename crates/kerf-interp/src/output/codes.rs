//! What every dialect's program is made of besides its motion: the laser process codes, every
//! value resolved, and the text of a comment made safe for every controller.

/// The process codes of a program, every value resolved (the machine file's `process` keys
/// over the dialect's [`Dialect::default_process`](super::Dialect::default_process)).
#[derive(Debug, Clone, PartialEq)]
pub struct ProcessCodes {
    /// Lines that switch the beam on, written as given.
    pub beam_on: Vec<String>,
    /// Lines that switch the beam off.
    pub beam_off: Vec<String>,
    /// Dwell at the pierce point with the beam on, seconds.
    pub pierce_dwell_s: f64,
    /// Height of the pierce point above the cut's start along the tool axis, mm.
    pub pierce_standoff: f64,
}

impl ProcessCodes {
    /// Time of the descent from the pierce point to the cut's start, seconds, at `feed`
    /// mm/min (the writer programs the descent at the cutting feed).
    pub fn descent_s(&self, feed: f64) -> f64 {
        if self.pierce_standoff > 0.0 && feed > 0.0 {
            self.pierce_standoff / (feed / 60.0)
        } else {
            0.0
        }
    }
}

/// The longest comment text [`comment_text`] returns, in bytes (the rest is cut and `...`
/// appended): LinuxCNC refuses lines over 255 characters.
pub const MAX_COMMENT: usize = 160;

/// Text made safe for a comment in every dialect: printable ASCII is kept except `(` and `)`,
/// which become `[` and `]` (a parenthesis would close or nest a LinuxCNC comment); every
/// other character (line feed, carriage return, NUL, tab, other control characters, Unicode
/// line separators, any non-ASCII) becomes the visible escape `\u{hex}`. The result has no
/// character that can end a line or a comment, so it can never start a new block; it is cut to
/// [`MAX_COMMENT`] bytes.
///
/// ```
/// use kerf_interp::comment_text;
/// assert_eq!(comment_text("hole\nG0 X1400\nM30"), "hole\\u{a}G0 X1400\\u{a}M30");
/// assert_eq!(comment_text(")G0X1("), "]G0X1[");
/// assert_eq!(comment_text("Stoßblech"), "Sto\\u{df}blech");
/// ```
pub fn comment_text(text: &str) -> String {
    escape(text, MAX_COMMENT)
}

/// The escaping of [`comment_text`], cut at `max` bytes.
pub(super) fn escape(text: &str, max: usize) -> String {
    let mut out = String::with_capacity(text.len().min(max) + 8);
    for c in text.chars() {
        let piece = match c {
            '(' => "[".to_string(),
            ')' => "]".to_string(),
            ' '..='~' => c.to_string(),
            _ => format!("\\u{{{:x}}}", c as u32),
        };
        if out.len() + piece.len() > max {
            out.push_str("...");
            break;
        }
        out.push_str(&piece);
    }
    out
}
