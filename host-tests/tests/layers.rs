//! No import cycle inside any crate: at every level of every crate's module tree, the
//! modules under one parent import each other one way only (layers), as ARCHITECTURE.md
//! draws them.
//!
//! Each crate's modules are read from its root (`mod x;` declarations, `#[cfg(test)]`
//! modules left out) and parsed with `syn`; every `crate::…`, `super::…` and `self::…` path
//! (in `use` trees, expressions, types, attributes' macros and macro bodies) is resolved to
//! the deepest module it names. A path from a module into one of its ancestors is fine (a
//! child may use its parent's items); any other edge joins the two children of their nearest
//! common parent, and the children of every parent must form no cycle.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use syn::visit::Visit;

mod common;
use common::Scratch;

/// A module: its path from the crate root (empty for the root) and its file.
struct Module {
    path: Vec<String>,
    file: PathBuf,
}

/// Whether the attributes hold `#[cfg(test)]`.
fn is_test(attrs: &[syn::Attribute]) -> bool {
    attrs.iter().any(|a| {
        a.path().is_ident("cfg")
            && a.meta
                .require_list()
                .is_ok_and(|l| l.tokens.to_string().trim() == "test")
    })
}

/// The file of child module `name` declared in `file` (whose own module path is `dir`-based).
fn child_file(file: &Path, is_root_or_mod: bool, name: &str, attrs: &[syn::Attribute]) -> PathBuf {
    let dir = if is_root_or_mod {
        file.parent().unwrap().to_path_buf()
    } else {
        file.with_extension("")
    };
    for a in attrs {
        if a.path().is_ident("path") {
            if let Ok(nv) = a.meta.require_name_value() {
                if let syn::Expr::Lit(syn::ExprLit {
                    lit: syn::Lit::Str(s),
                    ..
                }) = &nv.value
                {
                    return file.parent().unwrap().join(s.value());
                }
            }
        }
    }
    let flat = dir.join(format!("{name}.rs"));
    if flat.exists() {
        flat
    } else {
        dir.join(name).join("mod.rs")
    }
}

/// Every module of the crate rooted at `root` (its `lib.rs` or `main.rs`).
fn modules(root: &Path) -> Vec<Module> {
    let mut out = Vec::new();
    let mut todo = vec![(Vec::<String>::new(), root.to_path_buf(), true)];
    while let Some((path, file, root_or_mod)) = todo.pop() {
        let text =
            std::fs::read_to_string(&file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
        let ast = syn::parse_file(&text).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
        for item in &ast.items {
            if let syn::Item::Mod(m) = item {
                if m.content.is_none() && !is_test(&m.attrs) {
                    let f = child_file(&file, root_or_mod, &m.ident.to_string(), &m.attrs);
                    let is_mod = f.file_name().is_some_and(|n| n == "mod.rs");
                    let mut p = path.clone();
                    p.push(m.ident.to_string());
                    todo.push((p, f, is_mod));
                }
            }
        }
        out.push(Module { path, file });
    }
    out
}

/// Collects the module-relative paths a file uses.
#[derive(Default)]
struct Paths {
    found: Vec<Vec<String>>,
}

impl Paths {
    fn push(&mut self, segments: Vec<String>) {
        if matches!(
            segments.first().map(String::as_str),
            Some("crate" | "super" | "self")
        ) {
            self.found.push(segments);
        }
    }

    /// `crate :: a :: b` sequences in a macro's tokens.
    fn tokens(&mut self, tokens: proc_macro2::TokenStream) {
        let mut current: Vec<String> = Vec::new();
        let mut colons = 0;
        for t in tokens {
            match t {
                proc_macro2::TokenTree::Ident(i) => {
                    if colons == 2 || current.is_empty() {
                        if colons != 2 {
                            current.clear();
                        }
                        current.push(i.to_string());
                    } else {
                        let done = std::mem::take(&mut current);
                        self.push(done);
                        current.push(i.to_string());
                    }
                    colons = 0;
                }
                proc_macro2::TokenTree::Punct(p) if p.as_char() == ':' => colons += 1,
                proc_macro2::TokenTree::Group(g) => {
                    let done = std::mem::take(&mut current);
                    self.push(done);
                    colons = 0;
                    self.tokens(g.stream());
                }
                _ => {
                    let done = std::mem::take(&mut current);
                    self.push(done);
                    colons = 0;
                }
            }
        }
        self.push(current);
    }

    fn use_tree(&mut self, prefix: &mut Vec<String>, tree: &syn::UseTree) {
        match tree {
            syn::UseTree::Path(p) => {
                prefix.push(p.ident.to_string());
                self.use_tree(prefix, &p.tree);
                prefix.pop();
            }
            syn::UseTree::Name(n) => {
                let mut s = prefix.clone();
                s.push(n.ident.to_string());
                self.push(s);
            }
            syn::UseTree::Rename(r) => {
                let mut s = prefix.clone();
                s.push(r.ident.to_string());
                self.push(s);
            }
            syn::UseTree::Glob(_) => self.push(prefix.clone()),
            syn::UseTree::Group(g) => {
                for t in &g.items {
                    self.use_tree(prefix, t);
                }
            }
        }
    }
}

impl<'ast> Visit<'ast> for Paths {
    fn visit_item_mod(&mut self, m: &'ast syn::ItemMod) {
        if !is_test(&m.attrs) {
            syn::visit::visit_item_mod(self, m);
        }
    }
    fn visit_item_fn(&mut self, f: &'ast syn::ItemFn) {
        if !is_test(&f.attrs) {
            syn::visit::visit_item_fn(self, f);
        }
    }
    fn visit_item_use(&mut self, u: &'ast syn::ItemUse) {
        if !is_test(&u.attrs) {
            self.use_tree(&mut Vec::new(), &u.tree);
        }
    }
    fn visit_path(&mut self, p: &'ast syn::Path) {
        self.push(p.segments.iter().map(|s| s.ident.to_string()).collect());
        syn::visit::visit_path(self, p);
    }
    fn visit_macro(&mut self, m: &'ast syn::Macro) {
        self.tokens(m.tokens.clone());
        syn::visit::visit_macro(self, m);
    }
}

/// The cycles among sibling modules of the crate rooted at `root`, each as its members.
fn cycles(root: &Path) -> Vec<(String, Vec<String>)> {
    let mods = modules(root);
    let known: BTreeSet<Vec<String>> = mods.iter().map(|m| m.path.clone()).collect();
    // The deepest known module a path names, from module `from` (inline modules count as
    // their file's).
    let resolve = |from: &[String], path: &[String]| -> Option<Vec<String>> {
        let mut base: Vec<String> = from.to_vec();
        let mut rest = path;
        match rest.first().map(String::as_str) {
            Some("crate") => {
                base.clear();
                rest = &rest[1..];
            }
            _ => {
                while rest.first().map(String::as_str) == Some("super") {
                    base.pop()?;
                    rest = &rest[1..];
                }
                if rest.first().map(String::as_str) == Some("self") {
                    rest = &rest[1..];
                }
            }
        }
        let mut target = base;
        for s in rest {
            let mut t = target.clone();
            t.push(s.clone());
            if known.contains(&t) {
                target = t;
            } else {
                break;
            }
        }
        Some(target)
    };
    // Edges between the children of each parent.
    let mut graphs: BTreeMap<Vec<String>, BTreeMap<String, BTreeSet<String>>> = BTreeMap::new();
    for m in &mods {
        let text = std::fs::read_to_string(&m.file).unwrap();
        let ast = syn::parse_file(&text).unwrap();
        let mut paths = Paths::default();
        paths.visit_file(&ast);
        for p in paths.found {
            let Some(t) = resolve(&m.path, &p) else {
                continue;
            };
            // Into an ancestor, or into itself or below: no edge between siblings.
            if m.path.starts_with(&t) || t.starts_with(&m.path) {
                continue;
            }
            let common = m.path.iter().zip(&t).take_while(|(a, b)| a == b).count();
            let parent = m.path[..common].to_vec();
            let (a, b) = (m.path[common].clone(), t[common].clone());
            graphs
                .entry(parent)
                .or_default()
                .entry(a)
                .or_default()
                .insert(b);
        }
    }
    let mut out = Vec::new();
    for (parent, g) in graphs {
        for scc in strongly_connected(&g) {
            if scc.len() > 1 {
                let name = if parent.is_empty() {
                    "crate".to_string()
                } else {
                    format!("crate::{}", parent.join("::"))
                };
                out.push((name, scc));
            }
        }
    }
    out
}

/// Tarjan's strongly connected components.
fn strongly_connected(g: &BTreeMap<String, BTreeSet<String>>) -> Vec<Vec<String>> {
    struct State<'a> {
        g: &'a BTreeMap<String, BTreeSet<String>>,
        index: BTreeMap<String, usize>,
        low: BTreeMap<String, usize>,
        stack: Vec<String>,
        on: BTreeSet<String>,
        out: Vec<Vec<String>>,
    }
    fn visit(s: &mut State, v: &str) {
        let i = s.index.len();
        s.index.insert(v.to_string(), i);
        s.low.insert(v.to_string(), i);
        s.stack.push(v.to_string());
        s.on.insert(v.to_string());
        let next: Vec<String> = s.g.get(v).into_iter().flatten().cloned().collect();
        for w in next {
            if !s.index.contains_key(&w) {
                visit(s, &w);
                let lw = s.low[&w];
                let lv = s.low.get_mut(v).unwrap();
                *lv = (*lv).min(lw);
            } else if s.on.contains(&w) {
                let iw = s.index[&w];
                let lv = s.low.get_mut(v).unwrap();
                *lv = (*lv).min(iw);
            }
        }
        if s.low[v] == s.index[v] {
            let mut comp = Vec::new();
            while let Some(w) = s.stack.pop() {
                s.on.remove(&w);
                let done = w == v;
                comp.push(w);
                if done {
                    break;
                }
            }
            comp.sort();
            s.out.push(comp);
        }
    }
    let mut s = State {
        g,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on: BTreeSet::new(),
        out: Vec::new(),
    };
    let nodes: BTreeSet<String> = g
        .iter()
        .flat_map(|(a, bs)| std::iter::once(a.clone()).chain(bs.iter().cloned()))
        .collect();
    for v in nodes {
        if !s.index.contains_key(&v) {
            visit(&mut s, &v);
        }
    }
    s.out
}

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .unwrap()
        .to_path_buf()
}

fn assert_layered(root: &str) {
    let found = cycles(&workspace().join(root));
    assert!(
        found.is_empty(),
        "{root}: modules that import each other in a circle (under their parent):\n{}",
        found
            .iter()
            .map(|(p, c)| format!("  {p}: {}", c.join(" <-> ")))
            .collect::<Vec<_>>()
            .join("\n")
    );
}

#[test]
fn the_core_has_no_import_cycle() {
    assert_layered("core/src/lib.rs");
}

#[test]
fn the_firmware_library_and_binary_have_no_import_cycle() {
    assert_layered("firmware/src/lib.rs");
    assert_layered("firmware/src/main.rs");
}

#[test]
fn the_host_tool_and_its_readers_have_no_import_cycle() {
    assert_layered("host-tests/src/lib.rs");
    assert_layered("host-tests/io/src/lib.rs");
    assert_layered("host-tests/src/bin/impact.rs");
}

#[test]
fn the_python_extension_has_no_import_cycle() {
    assert_layered("host-tests/python/src/lib.rs");
}

#[test]
fn a_cycle_is_found() {
    // The check itself: two sibling modules that use each other.
    let scratch = Scratch::new();
    let lib = scratch.file("lib.rs", "mod a;\nmod b;\nmod c;\n");
    scratch.file("a.rs", "use crate::b::X;\npub struct Y;\n");
    scratch.file("b.rs", "pub struct X(crate::a::Y);\n");
    scratch.file("c.rs", "fn f() { super::a::Y; }\n");
    let found = cycles(&lib);
    assert_eq!(
        found,
        vec![("crate".to_string(), vec!["a".into(), "b".into()])]
    );
}
