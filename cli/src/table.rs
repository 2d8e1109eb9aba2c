//! Tables of results written as GitHub Markdown (numbers rounded for reading) and as CSV
//! (numbers in full precision), from one list of columns.

/// One cell of a table.
pub(crate) enum Cell {
    /// Text, written as is (commas and quotes become spaces in CSV).
    Text(String),
    /// A number: Markdown shows `decimals` decimals, CSV the shortest exact form.
    Number(f64, usize),
}

/// A column: Markdown title, CSV key, and the cell of a row.
pub(crate) struct Column<R> {
    pub title: &'static str,
    pub key: &'static str,
    pub cell: fn(&R) -> Cell,
}

/// The rows as a GitHub Markdown table.
pub(crate) fn markdown<R>(columns: &[Column<R>], rows: &[R]) -> String {
    let line = |cells: Vec<String>| format!("| {} |\n", cells.join(" | "));
    let mut out = line(columns.iter().map(|c| c.title.to_string()).collect());
    out += &line(columns.iter().map(|_| "---".to_string()).collect());
    for row in rows {
        out += &line(
            columns
                .iter()
                .map(|c| match (c.cell)(row) {
                    Cell::Text(t) => t,
                    Cell::Number(v, decimals) => format!("{v:.decimals$}"),
                })
                .collect(),
        );
    }
    out
}

/// The rows as CSV with a header line of keys.
pub(crate) fn csv<R>(columns: &[Column<R>], rows: &[R]) -> String {
    let keys: Vec<&str> = columns.iter().map(|c| c.key).collect();
    let mut out = keys.join(",") + "\n";
    for row in rows {
        let cells: Vec<String> = columns
            .iter()
            .map(|c| match (c.cell)(row) {
                Cell::Text(t) => t.replace([',', '"'], " "),
                Cell::Number(v, _) => v.to_string(),
            })
            .collect();
        out += &(cells.join(",") + "\n");
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn markdown_rounds_and_csv_keeps_precision() {
        let columns = [
            Column {
                title: "name",
                key: "name",
                cell: |r: &(&str, f64)| Cell::Text(r.0.to_string()),
            },
            Column {
                title: "value %",
                key: "value",
                cell: |r: &(&str, f64)| Cell::Number(r.1, 2),
            },
        ];
        let rows = [("a,b", 0.123456), ("c", 3.0)];
        assert_eq!(
            markdown(&columns, &rows),
            "| name | value % |\n| --- | --- |\n| a,b | 0.12 |\n| c | 3.00 |\n"
        );
        assert_eq!(csv(&columns, &rows), "name,value\na b,0.123456\nc,3\n");
    }
}
