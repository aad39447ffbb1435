//! Cell edits of delimited text: a valid fixture file with one thing made wrong.

/// `text` with `f(line, cells)` applied to the `sep`-separated cells of each 1-based line; every
/// line ends in `\n`.
pub fn edit_cells(text: &str, sep: char, mut f: impl FnMut(usize, &mut Vec<String>)) -> String {
    let mut out = String::new();
    for (i, l) in text.lines().enumerate() {
        let mut cells: Vec<String> = l.split(sep).map(str::to_owned).collect();
        f(i + 1, &mut cells);
        out.push_str(&cells.join(&sep.to_string()));
        out.push('\n');
    }
    out
}

/// [`edit_cells`] of comma-separated text.
pub fn edit_rows(text: &str, f: impl FnMut(usize, &mut Vec<String>)) -> String {
    edit_cells(text, ',', f)
}

/// Comma-separated `text` with cell `col` (0-based) of 1-based `line` replaced by `value`.
pub fn with_cell(text: &str, line: usize, col: usize, value: &str) -> String {
    edit_rows(text, |n, cells| {
        if n == line {
            cells[col] = value.to_owned();
        }
    })
}
