"""The "How to add" recipes (docs/architecture-recipes.md, reached from docs/architecture.md)
stay true: every path they name exists (a path with a <placeholder> is a file to create: its
folder must exist), and every symbol named "in" a file (`symbol` in `path`) occurs in that file."""
import os
import re

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
ARCHITECTURE = os.path.join(REPO, "docs", "architecture.md")
RECIPES = os.path.join(REPO, "docs", "architecture-recipes.md")

# A code span that is a repository path: a known top-level folder or file, then more.
TOP = ("kernels/", "core/", "cpu_reference/", "cuda/", "harness/", "experiments/", "apps/", "python/",
       "scripts/", "tests/", "configs/", "docs/", "cmake/", "CMakeLists.txt")
IDENTIFIER = re.compile(r"[A-Za-z_][A-Za-z0-9_]*(?:::[A-Za-z_][A-Za-z0-9_]*)*(?:\(\))?")
# What may stand between symbols that a following "in `path`" or "of `path`" places: commas,
# "and", "its row of", "its case of", ... but no sentence or clause end.
CONNECTOR = re.compile(r"^[\s,]*(?:(?:and|or|its|row|case|of|the|enumerator|interface|array|\w+'s)[\s,]*)*$")
PLACED = re.compile(r"^[\s,]*(?:(?:and|or|its|row|case|of|the|enumerator|interface|array|\w+'s)[\s,]*)*(?:in|of)\s+$")


def recipes_text():
    with open(RECIPES, encoding="utf-8") as f:
        text = f.read()
    assert text.startswith("# How to add\n"), "docs/architecture-recipes.md does not start with \"# How to add\""
    return text


def named_paths(text):
    spans = re.findall(r"`([^`\s]+)`", text)
    return sorted({s for s in spans if s.startswith(TOP)})


def symbols_in_files(text):
    """(symbol, path) pairs: `a`, `b` and `c` in `path`; and `path` (`a`, `b`)."""
    spans = [(m.start(), m.end(), m.group(1)) for m in re.finditer(r"`([^`]+)`", text)]
    pairs = []
    pending = []
    skip_to = 0  # the end of a path's parenthesised list, already placed
    for i, (start, end, span) in enumerate(spans):
        if start < skip_to:
            continue
        between = text[spans[i - 1][1]:start] if i else ""
        if span.startswith(TOP):
            if pending and PLACED.match(between):
                pairs += [(symbol, span) for symbol in pending]
            pending = []
            # A parenthesised list right after the path: `path` (`a`, `b`, ...).
            rest = text[end:]
            if rest.startswith(" ("):
                close = rest.find(")", 2)
                close = close if close >= 0 else 0
                skip_to = end + close
                for m in re.finditer(r"`([^`]+)`", rest[:close]):
                    if IDENTIFIER.fullmatch(m.group(1)):
                        pairs.append((m.group(1).rstrip("()"), span))
            continue
        if not IDENTIFIER.fullmatch(span):
            pending = []
            continue
        if pending and not CONNECTOR.match(between):
            pending = []
        pending.append(span.rstrip("()"))
    return pairs


def test_the_map_points_to_the_recipes():
    with open(ARCHITECTURE, encoding="utf-8") as f:
        text = f.read()
    assert "\n## How to add\n" in text, "docs/architecture.md has no section \"## How to add\""
    assert "(architecture-recipes.md)" in text, "docs/architecture.md does not link docs/architecture-recipes.md"


def test_every_recipe_is_there():
    text = recipes_text()
    for kind in ("A lattice kind", "A mesh format", "A sampler backend", "A peer"):
        assert "\n" + kind in text, f"the recipes lack \"{kind}\""


def test_every_named_path_exists():
    paths = named_paths(recipes_text())
    assert len(paths) > 30, f"too few paths found in the recipes: {paths}"
    missing = []
    for path in paths:
        if "<" in path:  # a file to create: its folder must exist
            folder = os.path.dirname(path)
            if not os.path.isdir(os.path.join(REPO, folder)):
                missing.append(f"{path} (folder {folder}/)")
        elif not os.path.exists(os.path.join(REPO, path)):
            missing.append(path)
    assert not missing, "docs/architecture-recipes.md names paths that do not exist: " + ", ".join(missing)


def test_every_symbol_is_in_its_file():
    pairs = symbols_in_files(recipes_text())
    assert len(pairs) > 10, f"too few `symbol` in `file` pairs found: {pairs}"
    wrong = []
    for symbol, path in pairs:
        if not path.startswith(TOP) or "<" in path:
            continue
        full = os.path.join(REPO, path)
        if not os.path.isfile(full):
            continue  # reported by test_every_named_path_exists
        with open(full, encoding="utf-8", errors="replace") as f:
            if symbol.split("::")[-1] not in f.read():
                wrong.append(f"{symbol} in {path}")
    assert not wrong, "docs/architecture-recipes.md names symbols their files lack: " + ", ".join(wrong)
