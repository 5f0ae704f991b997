#!/usr/bin/env python3
"""List import cycles between the module files of a crate's src/ directory.

Usage: python3 scripts/module_cycles.py [-v] [--leaves DIR] SRC_DIR [SRC_DIR ...]
       e.g. python3 scripts/module_cycles.py engines/src harness/src scenes/src

Each SRC_DIR is one crate (its root is lib.rs, else main.rs). A file depends on another when it
names an item the other file DEFINES: through `use crate::…`, `use super::…`, `use self::…`,
`use child::…`, a glob import (`use super::*` counts the names the file actually mentions), or
an inline path such as `crate::x::y`, `super::x`, `self::x` or `alias::x` after `use …::alias`.
A path that lands on a re-exported name (`pub use child::X;` in a parent) resolves to the file
that defines X. A parent's `mod child;` and its re-export lines are the module tree, not
dependencies. Comments and string literals are ignored (intra-doc links are not imports). A
file's own `macro_rules!` whose body declares modules (`$(mod $name;)*`) is expanded where it is
invoked with a list of names, so the modules a registry macro declares are checked too.

Prints each elementary cycle as `a.rs -> b.rs -> a.rs` (paths under SRC_DIR, at most 20 per
strongly connected group) and exits 1 if there is any, 0 if none, 2 on bad input. With
`--leaves DIR` (a folder under each SRC_DIR that has it, e.g. `commands`), a file outside DIR that
imports one inside it is reported too: DIR holds leaves that only the crate root dispatches to. `-v` also
prints, for each edge of a cycle, the lines that make it.
"""

import os
import re
import sys

KEYWORDS_DEF = {"fn", "struct", "enum", "trait", "type", "const", "static", "union", "macro_rules"}


def strip(src):
    """Blanks comments, string and char literals (keeps newlines, so line numbers hold)."""
    out = []
    i, n = 0, len(src)
    while i < n:
        c = src[i]
        if src.startswith("//", i):
            j = src.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif src.startswith("/*", i):
            depth, j = 1, i + 2
            while j < n and depth:
                if src.startswith("/*", j):
                    depth, j = depth + 1, j + 2
                elif src.startswith("*/", j):
                    depth, j = depth - 1, j + 2
                else:
                    j += 1
            out.append(re.sub(r"[^\n]", " ", src[i:j]))
            i = j
        elif re.match(r'b?r(#*)"', src[i:i + 260]) and (i == 0 or not (src[i - 1].isalnum() or src[i - 1] == "_")):
            m = re.match(r'b?r(#*)"', src[i:])
            close = '"' + m.group(1)
            j = src.find(close, i + m.end())
            j = n if j < 0 else j + len(close)
            out.append('""' + re.sub(r"[^\n]", " ", src[i + 2:j]))
            i = j
        elif c == '"':
            j = i + 1
            while j < n and src[j] != '"':
                j += 2 if src[j] == "\\" else 1
            j = min(j + 1, n)
            out.append('"' + re.sub(r"[^\n]", " ", src[i + 1:j - 1]) + '"')
            i = j
        elif c == "'":
            m = re.match(r"'(\\(x..|u\{[0-9a-fA-F]*\}|.)|[^\\\n])'", src[i:i + 12])
            if m:
                out.append("' '" + " " * (m.end() - 3))
                i += m.end()
            else:  # a lifetime or label
                out.append(c)
                i += 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


TOKEN = re.compile(r"\s*(::|[A-Za-z_][A-Za-z0-9_]*|\S)")


def tokens(text):
    """(token, line) pairs."""
    toks, pos, line = [], 0, 1
    while True:
        m = TOKEN.match(text, pos)
        if not m:
            break
        line += text.count("\n", pos, m.start(1))
        toks.append((m.group(1), line))
        pos = m.end()
    return toks


def expand_mod_macros(toks):
    """Rewrites invocations of a file's own `macro_rules!` that declare modules (`$(mod $x;)*` in
    the body, as `registry!` does) into plain `mod x;` lines, so the modules they declare are in the
    tree. The arguments must be a comma-separated list of identifiers."""
    names = set()
    for i, (t, _) in enumerate(toks):
        if t == "macro_rules" and i + 3 < len(toks) and toks[i + 1][0] == "!":
            depth, j = 0, i + 3
            while j < len(toks):
                if toks[j][0] in "{([":
                    depth += 1
                elif toks[j][0] in "})]":
                    depth -= 1
                    if depth == 0:
                        break
                elif toks[j][0] == "mod" and j + 1 < len(toks) and toks[j + 1][0] == "$":
                    names.add(toks[i + 2][0])
                j += 1
    if not names:
        return toks
    out, i = [], 0
    while i < len(toks):
        t, line = toks[i]
        if (
            t in names
            and i + 2 < len(toks)
            and toks[i + 1][0] == "!"
            and toks[i + 2][0] in "{("
            and (i == 0 or toks[i - 1][0] != "macro_rules")
        ):
            close = "}" if toks[i + 2][0] == "{" else ")"
            j = i + 3
            while j < len(toks) and toks[j][0] != close:
                name, nline = toks[j]
                if re.match(r"[A-Za-z_]", name):
                    out.extend([("mod", nline), (name, nline), (";", nline)])
                j += 1
            i = j + 1
            if i < len(toks) and toks[i][0] == ";":
                i += 1
            continue
        out.append((t, line))
        i += 1
    return out


def parse_use_tree(toks, i, prefix, out):
    """Parses one use tree at toks[i]; appends (path, name) with name '*' for globs. Returns next i."""
    path = list(prefix)
    while i < len(toks):
        t = toks[i][0]
        if t == "{":
            i += 1
            while i < len(toks) and toks[i][0] != "}":
                i = parse_use_tree(toks, i, path, out)
                if i < len(toks) and toks[i][0] == ",":
                    i += 1
            return i + 1
        if t == "*":
            out.append((path, "*"))
            return i + 1
        if t == "::":
            i += 1
            continue
        if re.match(r"[A-Za-z_]", t):
            path = path + [t]
            i += 1
            if i < len(toks) and toks[i][0] == "::":
                continue
            name = path[-1]
            if i + 1 < len(toks) and toks[i][0] == "as":
                name = toks[i + 1][0]
                i += 2
            if path[-1] == "self":  # `use a::b::{self}`
                path = path[:-1]
                name = path[-1] if name == "self" else name
            out.append((path, name))
            return i
        return i + 1  # unexpected token: give up on this tree
    return i


class Module:
    def __init__(self, path, file, parent):
        self.path = path  # tuple of names from the crate root
        self.file = file
        self.parent = parent
        self.children = {}  # name -> Module (file or inline)
        self.items = set()  # names defined here
        self.uses = []  # (path list, name, is_pub, line)
        self.globs = []  # (path list, is_pub, line)


class Crate:
    def __init__(self, src):
        self.src = src
        root = "lib.rs" if os.path.exists(os.path.join(src, "lib.rs")) else "main.rs"
        if not os.path.exists(os.path.join(src, root)):
            raise ValueError(f"{src}: no lib.rs or main.rs")
        self.files = {}  # rel file -> (tokens, [(token index range, module)])
        self.inline_paths = {}  # rel file -> list of (module, path list, line)
        self.idents = {}  # rel file -> list of (module, ident, line) for glob lookups
        self.root = Module((), root, None)
        self.load(root, self.root)

    def load(self, rel, module):
        full = os.path.join(self.src, rel)
        with open(full, encoding="utf-8") as f:
            toks = expand_mod_macros(tokens(strip(f.read())))
        self.files[rel] = toks
        self.inline_paths[rel] = []
        self.idents[rel] = []
        stack = [(0, module)]  # (brace depth at which the module's body closes, module)
        depth = 0
        i = 0
        in_use = False
        while i < len(toks):
            t, line = toks[i]
            cur = stack[-1][1]
            at = cur.file  # the node this token belongs to (a `#[cfg(test)]` module is its own)
            if t == "{":
                depth += 1
            elif t == "}":
                depth -= 1
                if len(stack) > 1 and depth < stack[-1][0]:
                    stack.pop()
            if t == "mod" and i + 1 < len(toks) and re.match(r"[A-Za-z_]", toks[i + 1][0]):
                name = toks[i + 1][0]
                nxt = toks[i + 2][0] if i + 2 < len(toks) else ";"
                child = Module(cur.path + (name,), rel, cur)
                cur.children[name] = child
                if nxt == "{" and self.cfg_test(toks, i):
                    child.file = f"{rel}#{name}"  # a test module is a node of its own
                    self.inline_paths[child.file] = []
                    self.idents[child.file] = []
                if nxt == "{":
                    depth += 1
                    stack.append((depth, child))
                    i += 3
                    continue
                if nxt == ";" and cur.file == rel and len(stack) == 1:
                    child.file = self.child_file(rel, name)
                    if child.file is not None:
                        self.load(child.file, child)
                    else:
                        del cur.children[name]
                i += 3
                continue
            if t == "use" and (i == 0 or toks[i - 1][0] not in ("::",)):
                is_pub = self.is_pub(toks, i)
                out = []
                j = parse_use_tree(toks, i + 1, [], out)
                for path, name in out:
                    if name == "*":
                        cur.globs.append((path, is_pub, line))
                    else:
                        cur.uses.append((path, name, is_pub, line))
                while j < len(toks) and toks[j][0] != ";":
                    j += 1
                i = j + 1
                continue
            if t in KEYWORDS_DEF and i + 1 < len(toks):
                k = i + 1
                if t == "macro_rules" and toks[k][0] == "!":
                    k += 1
                name = toks[k][0]
                if re.match(r"[A-Za-z_]", name) and name not in ("mut", "fn", "unsafe", "extern"):
                    cur.items.add(name)
            if re.match(r"[A-Za-z_]", t) and (i == 0 or toks[i - 1][0] != "::"):
                path = [t]
                j = i + 1
                while j + 1 < len(toks) and toks[j][0] == "::" and re.match(r"[A-Za-z_]", toks[j + 1][0]):
                    path.append(toks[j + 1][0])
                    j += 2
                if len(path) > 1:
                    self.inline_paths[at].append((cur, path, line))
                else:
                    self.idents[at].append((cur, t, line))
            i += 1

    @staticmethod
    def cfg_test(toks, i):
        """Whether the `mod` at toks[i] carries `#[cfg(test)]`."""
        j = i - 1
        if j >= 0 and toks[j][0] == ")":
            while j >= 0 and toks[j][0] != "(":
                j -= 1
            j -= 1
        if j >= 0 and toks[j][0] == "pub":
            j -= 1
        words = [t for t, _ in toks[max(0, j - 6):j + 1]]
        return words[-7:] == ["#", "[", "cfg", "(", "test", ")", "]"]

    @staticmethod
    def is_pub(toks, i):
        j = i - 1
        if j >= 0 and toks[j][0] == ")":  # pub(crate) / pub(super) / pub(in …)
            while j >= 0 and toks[j][0] != "(":
                j -= 1
            j -= 1
        return j >= 0 and toks[j][0] == "pub"

    def child_file(self, rel, name):
        d = os.path.dirname(rel)
        base = os.path.basename(rel)
        if base not in ("lib.rs", "main.rs", "mod.rs"):
            d = os.path.join(d, base[:-3])
        for cand in (os.path.join(d, name + ".rs"), os.path.join(d, name, "mod.rs")):
            if os.path.exists(os.path.join(self.src, cand)):
                return os.path.normpath(cand)
        return None

    # --- resolution -------------------------------------------------------------------------

    def start(self, module, path):
        """Module a path is relative to and the remaining segments, or None (extern / unknown)."""
        first = path[0]
        if first == "crate":
            return self.root, path[1:]
        if first == "self":
            return module, path[1:]
        if first == "super":
            m, rest = module, path
            while rest and rest[0] == "super":
                if m.parent is None:
                    return None
                m, rest = m.parent, rest[1:]
            return m, rest
        if first in module.children or first in module.items or self.alias(module, first):
            return module, path
        return None

    def alias(self, module, name):
        return [u for u in module.uses if u[1] == name]

    def walk(self, module, rest, seen):
        """Follows segments from module: ('module', m) or ('item', file) or None."""
        m = module
        for k, seg in enumerate(rest):
            if seg == "self" and k == len(rest) - 1:
                break
            if seg == "super":
                if m.parent is None:
                    return None
                m = m.parent
                continue
            if seg in m.children:
                m = m.children[seg]
                continue
            if seg in m.items:
                return ("item", m.file)
            r = None
            for path, name, _pub, _line in self.alias(m, seg):
                r = self.resolve(m, path, seen)
                if r:
                    break
            if r is None:
                for gpath, _pub, _line in m.globs:
                    key = ("glob", id(m), tuple(gpath), seg)
                    if key in seen:
                        continue
                    g = self.resolve(m, gpath, seen | {key})
                    if g and g[0] == "module":
                        r = self.walk(g[1], [seg], seen | {key})
                        if r:
                            break
            if r is None:
                return None
            if r[0] == "item":
                return r
            m = r[1]
        return ("module", m)

    def resolve(self, module, path, seen=frozenset()):
        key = (id(module), tuple(path))
        if key in seen or not path:
            return None
        st = self.start(module, path)
        if st is None:
            return None
        return self.walk(st[0], st[1], seen | {key})

    # --- edges ------------------------------------------------------------------------------

    def modules(self):
        out, todo = [], [self.root]
        while todo:
            m = todo.pop()
            out.append(m)
            todo.extend(m.children.values())
        return out

    def edges(self):
        """{(from file, to file): [evidence lines]}"""
        edges = {}

        def add(f, r, why):
            if r and r[0] == "item" and r[1] != f:
                edges.setdefault((f, r[1]), []).append(why)

        for m in self.modules():
            for path, name, is_pub, line in m.uses:
                if is_pub:
                    continue  # a re-export is the module tree, not a dependency
                add(m.file, self.resolve(m, path), f"{m.file}:{line}: use {'::'.join(path)}")
        # (`m.file` of a `#[cfg(test)]` inline module is `file#name`: test code is its own node,
        # as it would be in a `tests.rs` of its own, so a test's imports make no cycle.)
        for f, paths in self.inline_paths.items():
            for m, path, line in paths:
                if path[0] in ("crate", "self", "super") or path[0] in m.children or self.alias(m, path[0]):
                    add(f, self.resolve(m, path), f"{f}:{line}: {'::'.join(path)}")
        for f, ids in self.idents.items():
            for m, ident, line in ids:
                if ident in m.items or ident in m.children or self.alias(m, ident):
                    continue
                for gpath, is_pub, gline in m.globs:
                    if is_pub:
                        continue
                    g = self.resolve(m, gpath)
                    if g and g[0] == "module":
                        r = self.walk(g[1], [ident], frozenset())
                        if r:
                            add(f, r, f"{f}:{line}: {ident} (via {'::'.join(gpath)}::* at line {gline})")
                            break
        return edges


def sccs(nodes, adj):
    index, low, on, stack, out, counter = {}, {}, set(), [], [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in sorted(adj.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            out.append(sorted(comp))

    sys.setrecursionlimit(10000)
    for v in sorted(nodes):
        if v not in index:
            visit(v)
    return out


def cycles_in(comp, adj, limit=20):
    """Elementary cycles of one strongly connected group, each starting at its smallest file."""
    comp_set, found = set(comp), []
    for start in comp:
        allowed = {v for v in comp_set if v >= start}

        def dfs(v, path):
            if len(found) > limit:
                return
            for w in sorted(adj.get(v, ())):
                if w == start:
                    found.append(path + [start])
                elif w in allowed and w not in path:
                    dfs(w, path + [w])

        dfs(start, [start])
    return found


def main(argv):
    verbose = "-v" in argv
    leaves, dirs, args = [], [], [a for a in argv if a != "-v"]
    while args:
        a = args.pop(0)
        if a == "--leaves":
            if not args:
                print("module_cycles: --leaves needs a folder", file=sys.stderr)
                return 2
            leaves.append(args.pop(0).strip("/") + "/")
        else:
            dirs.append(a)
    if not dirs:
        print("usage: module_cycles.py [-v] [--leaves DIR] SRC_DIR [SRC_DIR ...]", file=sys.stderr)
        return 2
    total = 0
    for d in dirs:
        try:
            crate = Crate(d)
        except (OSError, ValueError) as e:
            print(f"module_cycles: {e}", file=sys.stderr)
            return 2
        edges = crate.edges()
        adj = {}
        for a, b in edges:
            adj.setdefault(a, set()).add(b)
        nodes = set(crate.files) | {m.file for m in crate.modules()}
        for leaf in leaves:
            for (a, b), why in sorted(edges.items()):
                inside = a.startswith(leaf) or a == crate.root.file
                if b.startswith(leaf) and not inside:
                    total += 1
                    print(f"{os.path.join(d, a)} imports {os.path.join(d, b)}: only the crate root imports {leaf}")
                    if verbose:
                        for w in why[:3]:
                            print(f"    {w}")
        for comp in sccs(nodes, adj):
            if len(comp) < 2:
                continue
            cyc = cycles_in(comp, adj)
            for c in cyc[:20]:
                total += 1
                print(" -> ".join(os.path.join(d, f) for f in c))
                if verbose:
                    for a, b in zip(c, c[1:]):
                        for why in edges[(a, b)][:3]:
                            print(f"    {why}")
            if len(cyc) > 20:
                print(f"  … more cycles among: {', '.join(comp)}")
    return 1 if total else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
