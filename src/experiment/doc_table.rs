//! Generated tables inside documents: the text between a begin and an end marker line is
//! replaced by a fresh table, so a document's figures come from a command.

use std::path::Path;

use anyhow::{Context, Result, bail};

/// Replace the text from the `begin` line through the `end` line of `file` by `table`
/// (which carries both markers itself); `what` names the table in the error.
pub fn replace_between(
    file: &Path,
    what: &str,
    (begin, end): (&str, &str),
    table: &str,
) -> Result<()> {
    let text =
        std::fs::read_to_string(file).with_context(|| format!("reading {}", file.display()))?;
    let (Some(a), Some(b)) = (text.find(begin), text.find(end)) else {
        bail!(
            "{}: no {what} table to update (add the two marker lines `{begin}` and `{end}` first)",
            file.display()
        );
    };
    let stop = b + end.len() + usize::from(text[b + end.len()..].starts_with('\n'));
    let new = format!("{}{table}{}", &text[..a], &text[stop..]);
    std::fs::write(file, new).with_context(|| format!("writing {}", file.display()))
}
