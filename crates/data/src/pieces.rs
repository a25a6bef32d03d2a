//! A CSV's data rows cut into pieces that parse on their own, so that they parse in parallel and
//! read exactly as one pass over the whole text would.
//!
//! A piece ends just after a line feed that
//! - closes every quote opened before it (an even number of `"` since the text began at a record
//!   start: every cell quoted by the standard holds its quotes in pairs),
//! - ends a line that holds text (a blank line's meaning depends on what follows it: an error
//!   before a row, allowed at the end of the file), and
//! - is followed by a line that holds text.
//!
//! A file whose quotes are not paired fails, in one pass, at the first unpaired one: the pieces
//! before it are cut correctly, and the first error in piece order is that one.

/// Where the pieces of `text` (which begins at a record start) end: at most `pieces` cuts near
/// equal shares, each a valid end, in increasing order; the last valid end of all is `last`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Cuts {
    /// Ends of the pieces before the last (byte offsets into the text).
    pub ends: Vec<usize>,
    /// The last offset at which a piece may end (`None`: none in the text).
    pub last: Option<usize>,
    /// Line feeds before each end in `ends`, then before `last`.
    pub line_feeds: Vec<usize>,
}

/// The valid ends of pieces of `text` near `pieces` equal shares (see the module).
pub(crate) fn cuts(text: &[u8], pieces: usize) -> Cuts {
    if memchr::memchr(b'"', text).is_some() {
        return cuts_after_every_quote(text, pieces);
    }
    // Without quotes every line feed ends a line: only the bytes near each share and at the end
    // are looked at, and the line feeds are counted by memchr.
    let share = (text.len() / pieces.max(1)).max(1);
    let mut cuts = Cuts {
        ends: Vec::new(),
        last: memchr::memrchr_iter(b'\n', text)
            .find(|&i| is_end(text, i))
            .map(|i| i + 1),
        line_feeds: Vec::new(),
    };
    let (mut counted, mut feeds) = (0, 0);
    for k in 1..pieces {
        // A piece may end at its share (the line feed just before it).
        let from = (k * share - 1).max(counted);
        let Some(end) = (memchr::memchr_iter(b'\n', &text[from.min(text.len())..]))
            .map(|i| from + i)
            .find(|&i| is_end(text, i))
            .map(|i| i + 1)
        else {
            break;
        };
        feeds += memchr::memchr_iter(b'\n', &text[counted..end]).count();
        cuts.ends.push(end);
        cuts.line_feeds.push(feeds);
        counted = end;
    }
    if let Some(last) = cuts.last {
        feeds += memchr::memchr_iter(b'\n', &text[counted..last]).count();
    }
    cuts.line_feeds.push(feeds);
    cuts
}

/// Whether the line feed at `i`, outside quotes, is a valid end (the module's last two rules).
fn is_end(text: &[u8], i: usize) -> bool {
    ends_a_line_with_text(text, i) && text_follows(text, i)
}

/// [`cuts`] of a text with quotes: every byte is looked at, to know which line feeds are outside
/// them.
fn cuts_after_every_quote(text: &[u8], pieces: usize) -> Cuts {
    let share = text.len() / pieces.max(1);
    let mut next_target = share.max(1);
    // An odd number of quotes so far: inside a quoted cell.
    let mut quoted = false;
    let mut line_feeds = 0usize;
    let mut cuts = Cuts {
        ends: Vec::new(),
        last: None,
        line_feeds: Vec::new(),
    };
    let mut last_line_feeds = 0;
    for (i, &byte) in text.iter().enumerate() {
        match byte {
            b'"' => quoted = !quoted,
            b'\n' => {
                line_feeds += 1;
                if !quoted && is_end(text, i) {
                    cuts.last = Some(i + 1);
                    last_line_feeds = line_feeds;
                    if i + 1 >= next_target && cuts.ends.len() + 1 < pieces {
                        cuts.ends.push(i + 1);
                        cuts.line_feeds.push(line_feeds);
                        next_target = i + 1 + share.max(1);
                    }
                }
            }
            _ => {}
        }
    }
    cuts.line_feeds.push(last_line_feeds);
    cuts
}

/// Whether the line feed at `i` ends a line that holds text (before an optional carriage return).
fn ends_a_line_with_text(text: &[u8], i: usize) -> bool {
    let end = if i > 0 && text[i - 1] == b'\r' {
        i - 1
    } else {
        i
    };
    end > 0 && !matches!(text[end - 1], b'\n' | b'\r')
}

/// Whether a line with text starts after the line feed at `i`.
fn text_follows(text: &[u8], i: usize) -> bool {
    text.get(i + 1).is_some_and(|b| !matches!(b, b'\n' | b'\r'))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pieces_end_between_lines_with_text_outside_quotes() {
        let text = b"1,2\n3,\"a\nb\"\n4,5\n\n6,7\n8,9\n";
        let cut = cuts(text, 8);
        // Not inside the quoted cell (9), not around the blank line (16, 17), not at the end (25).
        assert_eq!(cut.ends, vec![4, 12, 21]);
        assert_eq!(cut.last, Some(21));
        assert_eq!(cut.line_feeds, vec![1, 3, 6, 6]);
        for end in &cut.ends {
            assert_eq!(text[end - 1], b'\n');
        }
    }

    #[test]
    fn carriage_return_line_feeds_are_line_ends() {
        let cut = cuts(b"1,2\r\n3,4\r\n5,6\r\n", 3);
        assert_eq!(cut.ends, vec![5, 10]);
        assert_eq!(cut.last, Some(10));
    }

    #[test]
    fn without_quotes_the_ends_skip_blank_lines_too() {
        let text = b"1,2\n\n3,4\n5,6\n\n7,8\n9\n";
        let cut = cuts(text, 8);
        assert_eq!(cut.ends, vec![9, 18]);
        assert_eq!(cut.last, Some(18));
        assert_eq!(cut.line_feeds, vec![3, 6, 6]);
    }

    #[test]
    fn a_quote_left_open_allows_no_end_after_it() {
        let cut = cuts(b"1,2\n\"3,4\n5,6\n7,8\n", 4);
        assert_eq!(cut.ends, vec![4]);
        assert_eq!(cut.last, Some(4));
    }
}
