//! A report as data: a title and blocks (headings, paragraphs, lists, tables, figures), written as
//! Markdown or as one self-contained HTML page. Reproductions and the `check --suite` reports build a
//! [`Document`] from their typed results and hand it to one writer; each format supplies only its
//! syntax (as hyperfine's `MarkupExporter` does).
//!
//! ```
//! use rtbench_reports::{Document, Table};
//! let mut doc = Document::new("spd-stats: published vs measured");
//! doc.paragraph("Counts within 10%.");
//! let mut t = Table::new("", &["scene", "eye hits"]).numeric(&[false, true]);
//! t.push(vec!["balls4".into(), "263169".into()]);
//! doc.table(t);
//! assert!(doc.to_markdown().contains("| balls4 | 263169 |"));
//! assert!(doc.to_html().contains("<td class=\"n\">263169</td>"));
//! ```

use maud::{html, Markup, PreEscaped, Render, DOCTYPE};
use std::fmt::Write;

/// A table with a caption (a heading above it, empty for none), ready for Markdown or HTML.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Table {
    pub caption: String,
    pub header: Vec<String>,
    /// Which columns hold numbers (right-aligned).
    pub numeric: Vec<bool>,
    pub rows: Vec<Vec<String>>,
}

impl Table {
    /// An empty table with these column names, all left-aligned.
    pub fn new(caption: &str, header: &[&str]) -> Table {
        Table {
            caption: caption.to_string(),
            header: header.iter().map(|h| h.to_string()).collect(),
            numeric: vec![false; header.len()],
            rows: Vec::new(),
        }
    }

    /// Marks the numeric (right-aligned) columns.
    pub fn numeric(mut self, numeric: &[bool]) -> Table {
        self.numeric = numeric.to_vec();
        self.numeric.resize(self.header.len(), false);
        self
    }

    /// Appends a row; a short row is padded with empty cells.
    pub fn push(&mut self, mut row: Vec<String>) {
        row.resize(self.header.len().max(row.len()), String::new());
        self.rows.push(row);
    }

    pub fn to_markdown(&self) -> String {
        let mut s = String::new();
        if !self.caption.is_empty() {
            let _ = writeln!(s, "## {}\n", self.caption);
        }
        let _ = writeln!(s, "| {} |", self.header.join(" | "));
        let rule: Vec<&str> = (0..self.header.len())
            .map(|i| {
                if self.numeric.get(i) == Some(&true) {
                    "---:"
                } else {
                    "---"
                }
            })
            .collect();
        let _ = writeln!(s, "|{}|", rule.join("|"));
        for row in &self.rows {
            let cells: Vec<String> = row.iter().map(|c| md_cell(c)).collect();
            let _ = writeln!(s, "| {} |", cells.join(" | "));
        }
        s.push('\n');
        s
    }

    pub fn to_html(&self) -> String {
        self.markup().into_string()
    }

    /// The table as markup, its caption a heading above it.
    pub fn markup(&self) -> Markup {
        html! {
            @if !self.caption.is_empty() {
                h2 { (self.caption) }
            }
            table {
                thead { tr { @for h in &self.header { th { (Inline(h)) } } } }
                tbody {
                    @for row in &self.rows {
                        tr {
                            @for (i, cell) in row.iter().enumerate() {
                                @if self.numeric.get(i) == Some(&true) {
                                    td.n { (Inline(cell)) }
                                } @else {
                                    td { (Inline(cell)) }
                                }
                            }
                        }
                    }
                }
            }
        }
    }
}

/// One block of a document.
#[derive(Clone, Debug, PartialEq)]
pub enum Block {
    Heading(String),
    /// A paragraph: inline Markdown (`code`, **bold**) is kept in Markdown and rendered in HTML.
    Paragraph(String),
    List(Vec<String>),
    Table(Table),
    /// An image, by its path relative to the document, with a caption.
    Figure {
        path: String,
        caption: String,
    },
}

/// A report: a title and its blocks.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Document {
    pub title: String,
    pub blocks: Vec<Block>,
}

impl Document {
    pub fn new(title: impl Into<String>) -> Document {
        Document {
            title: title.into(),
            blocks: Vec::new(),
        }
    }
    pub fn heading(&mut self, text: impl Into<String>) {
        self.blocks.push(Block::Heading(text.into()));
    }
    pub fn paragraph(&mut self, text: impl Into<String>) {
        self.blocks.push(Block::Paragraph(text.into()));
    }
    pub fn list(&mut self, items: Vec<String>) {
        self.blocks.push(Block::List(items));
    }
    pub fn table(&mut self, t: Table) {
        self.blocks.push(Block::Table(t));
    }
    pub fn figure(&mut self, path: impl Into<String>, caption: impl Into<String>) {
        self.blocks.push(Block::Figure {
            path: path.into(),
            caption: caption.into(),
        });
    }
    /// Appends another document's blocks (its title becomes a heading).
    pub fn append(&mut self, other: Document) {
        if !other.title.is_empty() {
            self.heading(other.title);
        }
        self.blocks.extend(other.blocks);
    }

    pub fn to_markdown(&self) -> String {
        let mut s = format!("# {}\n\n", self.title);
        for b in &self.blocks {
            match b {
                Block::Heading(h) => {
                    let _ = writeln!(s, "## {h}\n");
                }
                Block::Paragraph(p) => {
                    let _ = writeln!(s, "{p}\n");
                }
                Block::List(items) => {
                    for i in items {
                        let _ = writeln!(s, "- {i}");
                    }
                    s.push('\n');
                }
                Block::Table(t) => s.push_str(&t.to_markdown()),
                Block::Figure { path, caption } => {
                    let _ = writeln!(s, "![{caption}]({path})\n");
                }
            }
        }
        s
    }

    /// One self-contained page (no script, no external resource).
    pub fn to_html(&self) -> String {
        let body = html! {
            h1 { (self.title) }
            @for b in &self.blocks {
                @match b {
                    Block::Heading(h) => h2 { (Inline(h)) },
                    Block::Paragraph(p) => p { (Inline(p)) },
                    Block::List(items) => ul { @for i in items { li { (Inline(i)) } } },
                    Block::Table(t) => (t.markup()),
                    Block::Figure { path, caption } => figure {
                        img src=(path) alt=(caption);
                        figcaption { (caption) }
                    },
                }
            }
        };
        page(&self.title, body).into_string()
    }
}

/// A self-contained page: the shared style, this title and body.
pub(crate) fn page(title: &str, body: Markup) -> Markup {
    html! {
        (DOCTYPE)
        html lang="en" {
            head {
                meta charset="utf-8";
                title { (title) }
                style { (PreEscaped(STYLE)) }
            }
            body { (body) }
        }
    }
}

pub(crate) const STYLE: &str = "body{font-family:system-ui,sans-serif;margin:2em auto;max-width:1300px;padding:0 1em;color:#222}\
table{border-collapse:collapse;margin:.5em 0 1em;font-size:14px}\
th,td{border:1px solid #ccc;padding:3px 8px}th{background:#f2f2f2}td.n{text-align:right;font-variant-numeric:tabular-nums}\
tr:nth-child(even) td{background:#fafafa}ul.env{list-style:none;padding:0}ul.env li{margin:2px 0}\
p.notes{font-size:13px;color:#555;max-width:60em}figure{margin:1em 0}svg,img{max-width:100%;height:auto}";

/// Keeps a Markdown cell a cell: a `|` inside would split it.
pub(crate) fn md_cell(text: &str) -> String {
    text.replace('|', "\\|").replace('\n', " ")
}

/// Text with the inline Markdown the documents use (`code` and **bold**) rendered as markup; the
/// text itself is escaped by maud.
pub struct Inline<'a>(pub &'a str);

impl Render for Inline<'_> {
    fn render(&self) -> Markup {
        html! {
            @for (i, part) in self.0.split('`').enumerate() {
                @if i % 2 == 1 {
                    code { (part) }
                } @else {
                    @for (j, p) in part.split("**").enumerate() {
                        @if j % 2 == 1 { b { (p) } } @else { (p) }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn markdown_and_html_carry_the_same_cells() {
        let mut d = Document::new("t");
        d.paragraph("a `b` **c**");
        let mut t = Table::new("cap", &["x", "y"]).numeric(&[false, true]);
        t.push(vec!["a|b".into(), "1.5".into()]);
        t.push(vec!["short".into()]);
        d.table(t);
        d.list(vec!["one".into()]);
        let md = d.to_markdown();
        assert!(md.starts_with("# t\n\na `b` **c**\n\n## cap\n\n| x | y |\n|---|---:|\n| a\\|b | 1.5 |\n| short |  |\n"));
        let html = d.to_html();
        assert!(html.contains("<p>a <code>b</code> <b>c</b></p>"));
        assert!(html.contains("<td>a|b</td><td class=\"n\">1.5</td>"));
        assert!(html.contains("<li>one</li>"));
        assert!(!html.contains("<script"));
    }

    #[test]
    fn html_escapes_markup_in_cells() {
        let mut t = Table::new("", &["<h>"]);
        t.push(vec!["<script>&".into()]);
        let h = t.to_html();
        assert!(h.contains("&lt;script&gt;&amp;"));
        assert!(h.contains("<th>&lt;h&gt;</th>"));
    }
}
