//! The MJCF document as an owned tree of elements, every `<include file>` spliced in.

use std::path::{Path, PathBuf};
use std::rc::Rc;

use crate::error::{Error, Result};

/// Most `<include>` files nested in one another \[files\]: deeper is read as a cycle.
const MAX_INCLUDE_DEPTH: usize = 16;

/// One XML element: its tag, attributes, child elements and where it was written.
#[derive(Debug, Clone)]
pub(crate) struct El {
    pub tag: String,
    pub attrs: Vec<(String, String)>,
    pub children: Vec<El>,
    /// The file (or `MJCF text`) the element is in.
    pub file: Rc<str>,
    /// Its line in that file (1-based).
    pub line: u32,
}

impl El {
    /// The attribute `name`, as written on the element.
    pub fn attr(&self, name: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|(k, _)| k == name)
            .map(|(_, v)| v.as_str())
    }

    /// The child elements with tag `tag`.
    pub fn elements<'a>(&'a self, tag: &'a str) -> impl Iterator<Item = &'a El> + 'a {
        self.children.iter().filter(move |c| c.tag == tag)
    }

    /// The element for messages: `<joint name="knee">` at `file:line`.
    pub fn at(&self) -> String {
        match self.attr("name") {
            Some(n) => format!("<{} name=\"{n}\"> at {}:{}", self.tag, self.file, self.line),
            None => format!("<{}> at {}:{}", self.tag, self.file, self.line),
        }
    }

    /// An error about this element.
    pub fn error(&self, message: impl std::fmt::Display) -> Error {
        Error::Parse {
            source_name: self.file.to_string(),
            line: self.line as usize,
            message: format!("{}: {message}", self.at()),
        }
    }
}

/// Where the document comes from: its folder (for `<include>`), the depth limit.
struct Reader<'a> {
    dir: Option<&'a Path>,
    max_depth: usize,
    /// The files being included, outermost first (a file including itself is a cycle).
    stack: Vec<PathBuf>,
}

/// The tag of the first element of `text` (after the XML declaration, comments and
/// whitespace), or `None` when `text` does not start like XML.
pub(crate) fn root_tag(text: &str) -> Option<&str> {
    let mut rest = text.trim_start_matches('\u{feff}');
    loop {
        rest = rest.trim_start();
        if let Some(r) = rest.strip_prefix("<?") {
            rest = &r[r.find("?>")? + 2..];
        } else if let Some(r) = rest.strip_prefix("<!--") {
            rest = &r[r.find("-->")? + 3..];
        } else if let Some(r) = rest.strip_prefix("<!") {
            rest = &r[r.find('>')? + 1..];
        } else {
            let r = rest.strip_prefix('<')?;
            let end = r
                .find(|c: char| c.is_whitespace() || c == '>' || c == '/')
                .unwrap_or(r.len());
            return Some(&r[..end]);
        }
    }
}

/// Parses the MJCF `text` (read from `name`, in the folder `dir` when known) into a tree whose
/// root is `<mujoco>`, every `<include file>` replaced by the children of the included file's
/// `<mujoco>` (its path taken relative to the including file's folder, else to `dir`, the main
/// model's folder).
///
/// Errors ([`Error::Parse`] naming the file and line): malformed XML, a root that is not
/// `<mujoco>`, an element nested deeper than `max_depth`, an `<include>` without `file`, that
/// cannot be read, with no folder to read it from, or that includes itself.
pub(crate) fn parse(text: &str, name: &str, dir: Option<&Path>, max_depth: usize) -> Result<El> {
    let mut r = Reader {
        dir,
        max_depth,
        stack: Vec::new(),
    };
    r.document(text, Rc::from(name))
}

impl Reader<'_> {
    fn document(&mut self, text: &str, file: Rc<str>) -> Result<El> {
        let text = text.trim_end_matches('\0');
        let doc = roxmltree::Document::parse(text).map_err(|e| Error::Parse {
            source_name: file.to_string(),
            line: e.pos().row as usize,
            message: format!("malformed XML: {e}"),
        })?;
        let root = doc.root_element();
        if root.tag_name().name() != "mujoco" {
            return Err(Error::Parse {
                source_name: file.to_string(),
                line: doc.text_pos_at(root.range().start).row as usize,
                message: format!(
                    "the root element is <{}>; an MJCF model's is <mujoco>",
                    root.tag_name().name()
                ),
            });
        }
        self.element(&doc, root, &file, 1)
    }

    fn element(
        &mut self,
        doc: &roxmltree::Document,
        node: roxmltree::Node,
        file: &Rc<str>,
        depth: usize,
    ) -> Result<El> {
        let line = doc.text_pos_at(node.range().start).row;
        if depth > self.max_depth {
            return Err(Error::ResourceLimit {
                what: format!("the element nesting depth at {file}:{line}"),
                value: depth.to_string(),
                limit: self.max_depth.to_string(),
                option: "ReadLimits::max_xml_depth (Robot::from_mjcf_str_with)".into(),
            });
        }
        let mut el = El {
            tag: node.tag_name().name().to_string(),
            attrs: node
                .attributes()
                .map(|a| (a.name().to_string(), a.value().to_string()))
                .collect(),
            children: Vec::new(),
            file: file.clone(),
            line,
        };
        for child in node.children().filter(|c| c.is_element()) {
            if child.tag_name().name() == "include" {
                let inc = self.element(doc, child, file, depth + 1)?;
                el.children.extend(self.include(&inc, depth)?);
            } else {
                el.children.push(self.element(doc, child, file, depth + 1)?);
            }
        }
        Ok(el)
    }

    /// The children of the `<mujoco>` of the file `inc` names, at `depth` in the including
    /// tree.
    fn include(&mut self, inc: &El, depth: usize) -> Result<Vec<El>> {
        let Some(rel) = inc.attr("file") else {
            return Err(inc.error("has no `file` attribute (expected the file to include)"));
        };
        let Some(main_dir) = self.dir else {
            return Err(inc.error(format!(
                "cannot include `{rel}` from text with no folder: read the model with Robot::from_mjcf_file (or give its folder)"
            )));
        };
        // Relative to the including file's folder (as MuJoCo does for nested includes), else
        // to the main model's.
        let here = self
            .stack
            .last()
            .and_then(|p| p.parent())
            .unwrap_or(main_dir);
        let path = [here.join(rel), main_dir.join(rel)]
            .into_iter()
            .find(|p| p.is_file())
            .unwrap_or_else(|| here.join(rel));
        if self.stack.contains(&path) || self.stack.len() >= MAX_INCLUDE_DEPTH {
            return Err(inc.error(format!(
                "`{rel}` is already being included (a cycle, or more than {MAX_INCLUDE_DEPTH} nested includes)"
            )));
        }
        let text = std::fs::read_to_string(&path)
            .map_err(|e| inc.error(format!("cannot read {}: {e}", path.display())))?;
        self.stack.push(path.clone());
        let root = self.document(&text, Rc::from(path.display().to_string().as_str()));
        self.stack.pop();
        let root = root?;
        if depth + root_depth(&root) > self.max_depth {
            return Err(Error::ResourceLimit {
                what: format!("the element nesting depth with {} included", path.display()),
                value: (depth + root_depth(&root)).to_string(),
                limit: self.max_depth.to_string(),
                option: "ReadLimits::max_xml_depth (Robot::from_mjcf_str_with)".into(),
            });
        }
        Ok(root.children)
    }
}

/// How deep the children of `el` nest below it (0 for a leaf).
fn root_depth(el: &El) -> usize {
    el.children
        .iter()
        .map(|c| 1 + root_depth(c))
        .max()
        .unwrap_or(0)
}
