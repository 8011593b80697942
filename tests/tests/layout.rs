//! The workspace's layout rules, checked on its source with `syn`:
//!
//! - in no crate does a module import, directly or through others, a module
//!   that imports it back (any `crate::`, `super::`, `self::` or child-module
//!   path outside `#[cfg(test)]` counts, a parent using its child's items
//!   included: re-exports in a parent are fine as long as the children name
//!   each other, not the parent);
//! - no function outside tests is longer than [`MAX_FN_LINES`] lines.
//!
//! Every library and binary of every workspace member is read from its root
//! file through its `mod` declarations, as rustc finds them. Paths inside
//! macro invocations are not seen (rustc expands them; `syn` does not).
//! A failure names each circle with one use per edge (file and line), or
//! each long function with its length.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use syn::visit::Visit;

/// The longest function allowed outside tests, in lines from `fn` to its
/// closing brace.
const MAX_FN_LINES: usize = 150;

/// A module's path inside its crate (`[]` is the crate root).
type ModPath = Vec<String>;

/// One module: where it is, its items (test-only items left out), and
/// what its names are: items it defines, names it imports (`use`, with
/// where they come from, crate-absolute, or `None` from another crate) and
/// modules it imports whole (`use x::*`).
struct Module {
    file: PathBuf,
    items: Vec<syn::Item>,
    defined: BTreeSet<String>,
    imported: BTreeMap<String, Option<ModPath>>,
    globs: Vec<ModPath>,
}

/// The modules of one crate target, by path.
type Crate = BTreeMap<ModPath, Module>;

fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("tests/ sits in the workspace")
        .to_path_buf()
}

/// The workspace members named in the root `Cargo.toml`.
fn members(root: &Path) -> Vec<PathBuf> {
    let manifest = std::fs::read_to_string(root.join("Cargo.toml")).expect("root Cargo.toml");
    let line = manifest
        .lines()
        .find(|line| line.trim_start().starts_with("members"))
        .expect("a members line in the root Cargo.toml");
    let list = &line[line.find('[').expect("[") + 1..line.rfind(']').expect("]")];
    list.split(',')
        .map(|name| name.trim().trim_matches('"'))
        .filter(|name| !name.is_empty())
        .map(|name| root.join(name))
        .collect()
}

/// The root files of a member's library and binaries.
fn target_roots(member: &Path) -> Vec<PathBuf> {
    let src = member.join("src");
    let mut roots: Vec<PathBuf> = ["lib.rs", "main.rs"]
        .iter()
        .map(|name| src.join(name))
        .filter(|path| path.is_file())
        .collect();
    if let Ok(entries) = std::fs::read_dir(src.join("bin")) {
        for entry in entries.flatten() {
            let path = entry.path();
            if path.extension().is_some_and(|ext| ext == "rs") {
                roots.push(path);
            } else if path.join("main.rs").is_file() {
                roots.push(path.join("main.rs"));
            }
        }
    }
    roots.sort();
    roots
}

/// Whether attributes make an item test-only (`#[cfg(test)]`,
/// `#[cfg(all(test, ...))]`, `#[test]`).
fn is_test(attrs: &[syn::Attribute]) -> bool {
    attrs.iter().any(|attr| {
        if attr.path().is_ident("test") {
            return true;
        }
        if !attr.path().is_ident("cfg") {
            return false;
        }
        let Ok(list) = attr.meta.require_list() else {
            return false;
        };
        let tokens = list.tokens.to_string().replace(' ', "");
        tokens == "test"
            || (tokens.starts_with("all(") && tokens.contains("test,"))
            || (tokens.starts_with("all(") && tokens.ends_with(",test)"))
    })
}

fn item_attrs(item: &syn::Item) -> &[syn::Attribute] {
    match item {
        syn::Item::Const(i) => &i.attrs,
        syn::Item::Enum(i) => &i.attrs,
        syn::Item::ExternCrate(i) => &i.attrs,
        syn::Item::Fn(i) => &i.attrs,
        syn::Item::ForeignMod(i) => &i.attrs,
        syn::Item::Impl(i) => &i.attrs,
        syn::Item::Macro(i) => &i.attrs,
        syn::Item::Mod(i) => &i.attrs,
        syn::Item::Static(i) => &i.attrs,
        syn::Item::Struct(i) => &i.attrs,
        syn::Item::Trait(i) => &i.attrs,
        syn::Item::TraitAlias(i) => &i.attrs,
        syn::Item::Type(i) => &i.attrs,
        syn::Item::Union(i) => &i.attrs,
        syn::Item::Use(i) => &i.attrs,
        _ => &[],
    }
}

/// The `#[path = "..."]` of a `mod` declaration, if any.
fn path_attr(attrs: &[syn::Attribute]) -> Option<String> {
    attrs.iter().find_map(|attr| match &attr.meta {
        syn::Meta::NameValue(nv) if nv.path.is_ident("path") => match &nv.value {
            syn::Expr::Lit(syn::ExprLit {
                lit: syn::Lit::Str(s),
                ..
            }) => Some(s.value()),
            _ => None,
        },
        _ => None,
    })
}

/// Reads a crate target from its root file.
fn read_crate(root: &Path) -> Crate {
    let mut modules = Crate::new();
    let dir = root
        .parent()
        .expect("a root file has a directory")
        .to_path_buf();
    read_file(root, Vec::new(), &dir, &mut modules);
    resolve_imports(&mut modules);
    modules
}

fn parse(file: &Path) -> syn::File {
    let text = std::fs::read_to_string(file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    syn::parse_file(&text).unwrap_or_else(|e| panic!("{}: {e}", file.display()))
}

/// Reads a module file; `children` is where its `mod x;` files live.
fn read_file(file: &Path, path: ModPath, children: &Path, modules: &mut Crate) {
    let parsed = parse(file);
    add_module(file, path, parsed.items, children, modules);
}

fn add_module(
    file: &Path,
    path: ModPath,
    items: Vec<syn::Item>,
    children: &Path,
    modules: &mut Crate,
) {
    let items: Vec<syn::Item> = items
        .into_iter()
        .filter(|item| !is_test(item_attrs(item)))
        .collect();
    for item in &items {
        let syn::Item::Mod(module) = item else {
            continue;
        };
        let name = module.ident.to_string();
        let mut child = path.clone();
        child.push(name.clone());
        match &module.content {
            Some((_, inner)) => {
                add_module(file, child, inner.clone(), &children.join(&name), modules);
            }
            None => {
                let child_file = match path_attr(&module.attrs) {
                    Some(p) => file.parent().expect("a file has a directory").join(p),
                    None if children.join(format!("{name}.rs")).is_file() => {
                        children.join(format!("{name}.rs"))
                    }
                    None => children.join(&name).join("mod.rs"),
                };
                let child_dir = if child_file.file_name().is_some_and(|n| n == "mod.rs") {
                    child_file
                        .parent()
                        .expect("mod.rs has a directory")
                        .to_path_buf()
                } else {
                    child_file.with_extension("")
                };
                read_file(&child_file, child, &child_dir, modules);
            }
        }
    }
    let defined = items.iter().filter_map(defined_name).collect();
    modules.insert(
        path,
        Module {
            file: file.to_path_buf(),
            items,
            defined,
            imported: BTreeMap::new(),
            globs: Vec::new(),
        },
    );
}

/// The name an item defines in its module's namespace, if any.
fn defined_name(item: &syn::Item) -> Option<String> {
    let ident = match item {
        syn::Item::Const(i) => &i.ident,
        syn::Item::Enum(i) => &i.ident,
        syn::Item::Fn(i) => &i.sig.ident,
        syn::Item::Macro(i) => i.ident.as_ref()?,
        syn::Item::Mod(i) => &i.ident,
        syn::Item::Static(i) => &i.ident,
        syn::Item::Struct(i) => &i.ident,
        syn::Item::Trait(i) => &i.ident,
        syn::Item::TraitAlias(i) => &i.ident,
        syn::Item::Type(i) => &i.ident,
        syn::Item::Union(i) => &i.ident,
        _ => return None,
    };
    Some(ident.to_string())
}

/// A path as written in module `here`, made crate-absolute; `None` when it
/// names another crate (or a prelude or local name).
fn absolute(modules: &Crate, here: &ModPath, segments: &[String]) -> Option<ModPath> {
    let first = segments.first()?;
    Some(match first.as_str() {
        "crate" => segments[1..].to_vec(),
        "self" => [here.clone(), segments[1..].to_vec()].concat(),
        "super" => {
            let mut base = here.clone();
            let mut rest = segments;
            while rest.first().is_some_and(|s| s == "super") {
                base.pop();
                rest = &rest[1..];
            }
            [base, rest.to_vec()].concat()
        }
        name => {
            let in_here = [here.clone(), vec![name.to_string()]].concat();
            let module = &modules.get(here)?;
            if modules.contains_key(&in_here) || module.defined.contains(name) {
                [here.clone(), segments.to_vec()].concat()
            } else if let Some(imported) = module.imported.get(name) {
                [imported.clone()?, segments[1..].to_vec()].concat()
            } else {
                let glob = module.globs.iter().find(|glob| {
                    modules
                        .get(*glob)
                        .is_some_and(|m| m.defined.contains(name) || m.imported.contains_key(name))
                })?;
                [glob.clone(), segments.to_vec()].concat()
            }
        }
    })
}

/// Fills in each module's imports (after every module is known).
fn resolve_imports(modules: &mut Crate) {
    let paths: Vec<ModPath> = modules.keys().cloned().collect();
    for path in paths {
        let mut leaves = Vec::new();
        for item in &modules[&path].items {
            if let syn::Item::Use(u) = item {
                use_leaves(&mut Vec::new(), &u.tree, &mut leaves);
            }
        }
        // Imports may name each other (`use a::b; use b::c;`): twice over.
        for _ in 0..2 {
            for (name, segments) in &leaves {
                let target = absolute(modules, &path, segments);
                let module = modules.get_mut(&path).expect("a known module");
                match name {
                    Some(name) => {
                        module.imported.insert(name.clone(), target);
                    }
                    None => {
                        if let Some(target) = target {
                            if !module.globs.contains(&target) {
                                module.globs.push(target);
                            }
                        }
                    }
                }
            }
        }
    }
}

/// A use tree's leaves: (the name it binds, or `None` for a glob; the path).
fn use_leaves(
    prefix: &mut Vec<String>,
    tree: &syn::UseTree,
    out: &mut Vec<(Option<String>, Vec<String>)>,
) {
    match tree {
        syn::UseTree::Path(p) => {
            prefix.push(p.ident.to_string());
            use_leaves(prefix, &p.tree, out);
            prefix.pop();
        }
        syn::UseTree::Name(n) => {
            let mut path = prefix.clone();
            if n.ident != "self" {
                path.push(n.ident.to_string());
            }
            let name = path.last().cloned();
            out.push((name, path));
        }
        syn::UseTree::Rename(r) => {
            let mut path = prefix.clone();
            if r.ident != "self" {
                path.push(r.ident.to_string());
            }
            out.push((Some(r.rename.to_string()), path));
        }
        syn::UseTree::Glob(_) => out.push((None, prefix.clone())),
        syn::UseTree::Group(g) => {
            for tree in &g.items {
                use_leaves(prefix, tree, out);
            }
        }
    }
}

/// The module that defines what a crate-absolute path names, following
/// imports and re-exports; `None` when it is another crate's.
fn defining_module(modules: &Crate, full: &[String], depth: usize) -> Option<ModPath> {
    let mut k = full.len();
    while !modules.contains_key(&full[..k]) {
        k = k.checked_sub(1)?;
    }
    let (module_path, rest) = (full[..k].to_vec(), &full[k..]);
    let Some(name) = rest.first() else {
        return Some(module_path);
    };
    let module = &modules[&module_path];
    if module.defined.contains(name) || depth > 16 {
        return Some(module_path);
    }
    if let Some(target) = module.imported.get(name) {
        let target = target.as_ref()?;
        return defining_module(
            modules,
            &[target.clone(), rest[1..].to_vec()].concat(),
            depth + 1,
        );
    }
    for glob in &module.globs {
        let through = defining_module(modules, &[glob.clone(), rest.to_vec()].concat(), depth + 1);
        if let Some(found) = through {
            let named_there = modules[&found].defined.contains(name)
                || modules[&found].imported.contains_key(name);
            if named_there {
                return Some(found);
            }
        }
    }
    Some(module_path)
}

/// Where one use of another module is: for the failure message.
#[derive(Clone)]
struct Site {
    file: PathBuf,
    line: usize,
}

/// Collects the modules a module's items name, with one site each.
struct Uses<'a> {
    modules: &'a Crate,
    here: &'a ModPath,
    file: &'a Path,
    found: BTreeMap<ModPath, Site>,
}

impl Uses<'_> {
    /// Resolves a path (as written) to the module defining what it names,
    /// through imports and re-exports, and records it when it is another
    /// module.
    fn note(&mut self, segments: &[String], line: usize) {
        let Some(full) = absolute(self.modules, self.here, segments) else {
            return;
        };
        let Some(target) = defining_module(self.modules, &full, 0) else {
            return;
        };
        if &target != self.here {
            self.found.entry(target).or_insert(Site {
                file: self.file.to_path_buf(),
                line,
            });
        }
    }
}

impl Uses<'_> {
    /// Notes the paths in a macro's tokens.
    fn scan_tokens(&mut self, tokens: proc_macro2::TokenStream) {
        use proc_macro2::{Spacing, TokenTree};
        let tokens: Vec<TokenTree> = tokens.into_iter().collect();
        let mut path: Vec<String> = Vec::new();
        let mut line = 0;
        let mut after_colons = false;
        let mut i = 0;
        while i < tokens.len() {
            match &tokens[i] {
                TokenTree::Ident(ident) if path.is_empty() || after_colons => {
                    if path.is_empty() {
                        line = ident.span().start().line;
                    }
                    path.push(ident.to_string());
                    after_colons = false;
                }
                TokenTree::Punct(p)
                    if p.as_char() == ':'
                        && p.spacing() == Spacing::Joint
                        && matches!(tokens.get(i + 1), Some(TokenTree::Punct(q)) if q.as_char() == ':')
                        && !path.is_empty() =>
                {
                    after_colons = true;
                    i += 1;
                }
                other => {
                    self.note(&std::mem::take(&mut path), line);
                    after_colons = false;
                    match other {
                        TokenTree::Group(group) => self.scan_tokens(group.stream()),
                        TokenTree::Ident(ident) => {
                            line = ident.span().start().line;
                            path.push(ident.to_string());
                        }
                        _ => {}
                    }
                }
            }
            i += 1;
        }
        self.note(&path, line);
    }
}

impl<'ast> Visit<'ast> for Uses<'_> {
    fn visit_item(&mut self, item: &'ast syn::Item) {
        if is_test(item_attrs(item)) {
            return;
        }
        // Inline modules are modules of their own.
        if let syn::Item::Mod(_) = item {
            return;
        }
        syn::visit::visit_item(self, item);
    }

    fn visit_impl_item_fn(&mut self, f: &'ast syn::ImplItemFn) {
        if !is_test(&f.attrs) {
            syn::visit::visit_impl_item_fn(self, f);
        }
    }

    /// An import is counted where its name is used: a re-export alone
    /// (`pub use part::Thing` in a facade) is not a dependency of the
    /// module's own code.
    fn visit_item_use(&mut self, _: &'ast syn::ItemUse) {}

    /// Macro bodies (`select!`, `vec!`, `format!` arguments, ...) are read
    /// as tokens: every `a::b::c` or lone name in them is a path.
    fn visit_macro(&mut self, mac: &'ast syn::Macro) {
        self.scan_tokens(mac.tokens.clone());
        syn::visit::visit_macro(self, mac);
    }

    /// `pub(super)`, `pub(in crate::x)`: who may see an item, not a use.
    fn visit_visibility(&mut self, _: &'ast syn::Visibility) {}

    fn visit_path(&mut self, path: &'ast syn::Path) {
        let segments: Vec<String> = path.segments.iter().map(|s| s.ident.to_string()).collect();
        if path.leading_colon.is_none() {
            let line = path.segments[0].ident.span().start().line;
            self.note(&segments, line);
        }
        syn::visit::visit_path(self, path);
    }
}

/// Which modules each module uses, with a site per edge.
fn edges(modules: &Crate) -> BTreeMap<ModPath, BTreeMap<ModPath, Site>> {
    modules
        .iter()
        .map(|(path, module)| {
            let mut uses = Uses {
                modules,
                here: path,
                file: &module.file,
                found: BTreeMap::new(),
            };
            for item in &module.items {
                uses.visit_item(item);
            }
            (path.clone(), uses.found)
        })
        .collect()
}

/// The strongly connected components with more than one module (Tarjan).
fn circles(graph: &BTreeMap<ModPath, BTreeMap<ModPath, Site>>) -> Vec<Vec<ModPath>> {
    struct State<'g> {
        graph: &'g BTreeMap<ModPath, BTreeMap<ModPath, Site>>,
        index: BTreeMap<&'g ModPath, usize>,
        low: BTreeMap<&'g ModPath, usize>,
        stack: Vec<&'g ModPath>,
        on_stack: BTreeSet<&'g ModPath>,
        out: Vec<Vec<ModPath>>,
    }
    fn connect<'g>(s: &mut State<'g>, v: &'g ModPath) {
        let n = s.index.len();
        s.index.insert(v, n);
        s.low.insert(v, n);
        s.stack.push(v);
        s.on_stack.insert(v);
        for w in s.graph[v].keys() {
            if !s.index.contains_key(w) {
                connect(s, w);
                let low = s.low[v].min(s.low[w]);
                s.low.insert(v, low);
            } else if s.on_stack.contains(w) {
                let low = s.low[v].min(s.index[w]);
                s.low.insert(v, low);
            }
        }
        if s.low[v] == s.index[v] {
            let mut component = Vec::new();
            loop {
                let w = s.stack.pop().expect("v is on the stack");
                s.on_stack.remove(w);
                component.push(w.clone());
                if w == v {
                    break;
                }
            }
            if component.len() > 1 {
                component.sort();
                s.out.push(component);
            }
        }
    }
    let mut state = State {
        graph,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on_stack: BTreeSet::new(),
        out: Vec::new(),
    };
    for v in graph.keys() {
        if !state.index.contains_key(v) {
            connect(&mut state, v);
        }
    }
    state.out
}

fn name(path: &ModPath) -> String {
    if path.is_empty() {
        "(crate root)".to_string()
    } else {
        path.join("::")
    }
}

fn relative(root: &Path, file: &Path) -> String {
    file.strip_prefix(root)
        .unwrap_or(file)
        .display()
        .to_string()
}

/// Every crate target of the workspace: (root file, modules).
fn all_crates() -> Vec<(PathBuf, Crate)> {
    let root = workspace_root();
    members(&root)
        .iter()
        .flat_map(|member| target_roots(member))
        .map(|file| {
            let modules = read_crate(&file);
            (file, modules)
        })
        .collect()
}

#[test]
fn no_module_imports_a_module_that_imports_it_back() {
    let root = workspace_root();
    let crates = all_crates();
    assert!(
        crates.len() >= 10,
        "found only {} crate targets: is the members list read right?",
        crates.len()
    );
    let mut report = String::new();
    for (file, modules) in &crates {
        let graph = edges(modules);
        for circle in circles(&graph) {
            report += &format!(
                "{}: a circle of {} modules\n",
                relative(&root, file),
                circle.len()
            );
            for from in &circle {
                for (to, site) in &graph[from] {
                    if circle.contains(to) {
                        report += &format!(
                            "    {} -> {}  ({}:{})\n",
                            name(from),
                            name(to),
                            relative(&root, &site.file),
                            site.line
                        );
                    }
                }
            }
        }
    }
    assert!(
        report.is_empty(),
        "modules that import each other:\n{report}"
    );
}

/// Collects functions longer than the bound, skipping test-only items.
struct LongFns<'a> {
    file: &'a Path,
    found: Vec<(usize, String)>,
}

impl LongFns<'_> {
    fn check(&mut self, name: &syn::Ident, start: usize, end: usize) {
        let lines = end + 1 - start;
        if lines > MAX_FN_LINES {
            self.found
                .push((lines, format!("{}:{start} {name}", self.file.display())));
        }
    }
}

impl<'ast> Visit<'ast> for LongFns<'_> {
    fn visit_item(&mut self, item: &'ast syn::Item) {
        if !is_test(item_attrs(item)) && !matches!(item, syn::Item::Mod(_)) {
            syn::visit::visit_item(self, item);
        }
    }

    fn visit_item_fn(&mut self, f: &'ast syn::ItemFn) {
        let start = f.sig.fn_token.span.start().line;
        let end = f.block.brace_token.span.close().end().line;
        self.check(&f.sig.ident, start, end);
        syn::visit::visit_item_fn(self, f);
    }

    fn visit_impl_item_fn(&mut self, f: &'ast syn::ImplItemFn) {
        if is_test(&f.attrs) {
            return;
        }
        let start = f.sig.fn_token.span.start().line;
        let end = f.block.brace_token.span.close().end().line;
        self.check(&f.sig.ident, start, end);
        syn::visit::visit_impl_item_fn(self, f);
    }

    fn visit_trait_item_fn(&mut self, f: &'ast syn::TraitItemFn) {
        if let Some(block) = &f.default {
            let start = f.sig.fn_token.span.start().line;
            let end = block.brace_token.span.close().end().line;
            self.check(&f.sig.ident, start, end);
        }
        syn::visit::visit_trait_item_fn(self, f);
    }
}

#[test]
fn no_function_outside_tests_is_longer_than_150_lines() {
    let root = workspace_root();
    let mut files = BTreeMap::new();
    for (_, modules) in all_crates() {
        for module in modules.into_values() {
            files
                .entry(module.file.clone())
                .or_insert_with(Vec::new)
                .extend(module.items);
        }
    }
    let mut found = Vec::new();
    for (file, items) in &files {
        let shown = PathBuf::from(relative(&root, file));
        let mut long = LongFns {
            file: &shown,
            found: Vec::new(),
        };
        for item in items {
            long.visit_item(item);
        }
        found.extend(long.found);
    }
    found.sort_by(|a, b| b.cmp(a));
    let report: String = found
        .iter()
        .map(|(lines, at)| format!("    {lines:4} lines  {at}\n"))
        .collect();
    assert!(
        found.is_empty(),
        "functions over {MAX_FN_LINES} lines (split them into named steps):\n{report}"
    );
}

/// The checker itself: a circle through a name the parent uses is found; a
/// one-way chain, a parent that only re-exports a child, and test-only
/// modules are not.
#[test]
fn the_circle_check_sees_circles_and_only_circles() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let write = |name: &str, text: &str| {
        let path = dir.path().join(name);
        std::fs::create_dir_all(path.parent().expect("a parent")).expect("mkdir");
        std::fs::write(path, text).expect("write");
    };
    write(
        "lib.rs",
        "mod a; mod b; mod c; mod d; mod e; pub use a::A; pub use d::D; pub struct R;\n\
         pub fn h() -> A { A }\n\
         fn i() -> e::E { e::E }\n\
         #[cfg(test)] mod t { fn f() -> crate::c::C { crate::c::C } }",
    );
    write(
        "a.rs",
        "pub struct A; pub fn f() -> crate::b::B { crate::b::B }",
    );
    // Through a name the root defines, not one it re-exports.
    write("b.rs", "pub struct B; use super::R; pub fn k() -> R { R }");
    write("c.rs", "pub struct C; pub fn g() { let _ = crate::b::B; }");
    // Only re-exported by the root: a facade, not a circle.
    write("d.rs", "pub struct D; pub fn g() { let _ = crate::h(); }");
    // Used by the root; `pub(super)` only says who may see it.
    write("e.rs", "pub(super) struct E;");
    let modules = read_crate(&dir.path().join("lib.rs"));
    let graph = edges(&modules);
    let found = circles(&graph);
    let v = |s: &[&str]| s.iter().map(|x| x.to_string()).collect::<Vec<_>>();
    assert_eq!(found, vec![vec![v(&[]), v(&["a"]), v(&["b"])]]);
    assert!(graph[&v(&["c"])].contains_key(&v(&["b"])));
    assert!(graph[&v(&["d"])].contains_key(&v(&[])));
    assert!(
        !graph[&v(&[])].contains_key(&v(&["d"])),
        "a re-export counted"
    );
    assert!(
        !graph[&v(&[])].contains_key(&v(&["c"])),
        "a test-only use counted"
    );
}
