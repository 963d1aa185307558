"""The runs a report is made of: experiment, kind, run id, commit, machine, build, load, and
the regression check when the run records one."""

import os
import re

from .tables import Table, number


def machine(run):
    prov = run.provenance
    cpu = "%s x%d" % (prov["cpu"]["model"], prov["cpu"]["hardware_threads"])
    gpu = prov["gpu"]["name"] if prov["gpu"] else "none"
    return cpu, gpu


def commit(run):
    git = run.provenance["git"]
    text = git["commit"][:10]
    if git.get("source") == "SDF_SOURCE_COMMIT":  # a tree without .git, the commit passed in
        text += " (passed in)"
    if git["dirty"]:
        text += " (dirty)"
    source = (run.published or {}).get("source_commit")
    return text if not source else "%s, built from %s" % (text, source)


def load_text(run):
    """'0.08/0.38': the 1-minute load average at start and end; 'not recorded' where absent."""
    load = run.provenance.get("load_average")
    if not load:
        return "not recorded"
    return "/".join(number(load[k][0], 2) if load[k] else "unknown" for k in ("start", "end"))


def overloaded(run):
    """True when the 1-minute load at the start or end exceeded the machine's hardware threads."""
    load = run.provenance.get("load_average")
    threads = run.provenance["cpu"]["hardware_threads"]
    return bool(load) and any(load[k] and load[k][0] > threads for k in ("start", "end"))


def check_text(run):
    check = run.manifest.get("check")
    if check is None:
        return "not checked"
    if check["passed"]:
        return "passed (%d ok, %d not comparable)" % (check["ok"], check["not_comparable"])
    return "FAILED (%d failed, %d missing)" % (check["failed"], check["missing"])


def source_text(run, repo):
    path = os.path.abspath(run.path)
    return os.path.relpath(path, repo) if path.startswith(repo + os.sep) else path


HEADING = "Runs"
HEADER = ["experiment", "kind", "run", "commit", "CPU", "GPU", "build", "load (start/end)", "check"]
PUBLISHED = "%s is a published run ("
LOADED = "Made on a loaded machine (load above its hardware threads): "
LOAD_TEXT = ("Load: the 1-minute load average when the run started and ended; timings from a machine whose load "
             "exceeds its hardware threads are not representative. Check: the regression check against the "
             "run's baseline, when the run was made with --check and records it.")
DIRTY_TEXT = ("Runs marked dirty were made from a work tree with uncommitted changes (or without git: commit "
              "\"unknown\"; a tree without .git records the commit passed in as SDF_SOURCE_COMMIT, \"(passed in)\").")
LOADED_TAIL = ". Their times and speedups are inflated or compressed by other work; errors and counts are unaffected."


def row(run):
    cpu, gpu = machine(run)
    return [run.name, run.kind, run.run_id, commit(run), cpu, gpu, run.provenance["build"]["build_type"], load_text(run),
            check_text(run)]


def published_text(run, repo):
    return (PUBLISHED + "%s, scripts/publish-gpu-results)%s") % (
        run.name, source_text(run, repo), ": " + run.published["note"] if "note" in run.published else ".")


def section(doc, runs, repo):
    doc.heading(2, HEADING)
    if not runs:
        doc.note("No runs found. Run a study first, e.g. `build/bin/run-experiment configs/ci_smoke.json`.")
        return
    table = Table(HEADER)
    for r in runs:
        table.add(row(r))
    doc.table(table)
    doc.paragraph(LOAD_TEXT)
    for r in runs:
        if r.published is not None:
            doc.paragraph(published_text(r, repo))
    loaded = [r.name for r in runs if overloaded(r)]
    if loaded:
        doc.note(LOADED + ", ".join(loaded) + LOADED_TAIL)
    if any(r.provenance["git"]["dirty"] for r in runs):
        doc.note(DIRTY_TEXT)


class OverviewError(Exception):
    """An existing report's overview that cannot be read back (rewritten())."""


def rewritten(doc, markdown, runs, repo):
    """Fills `doc` with the overview of an existing report (its Markdown) in which the entries
    of `runs`' experiments are made from `runs`: their table rows (where the experiment's
    first row was; a new experiment's after the last), their published-run paragraphs and
    their names in the loaded-machine note. The other experiments' entries, whose runs may no
    longer be on disk, are kept as written. A report without an overview gets one of `runs`."""
    begin = markdown.find("## %s\n" % HEADING)
    if begin < 0:
        section(doc, runs, repo)
        return
    end = markdown.find("\n## ", begin)
    lines = markdown[begin:len(markdown) if end < 0 else end].split("\n")
    names = {r.name for r in runs}
    table, published, loaded = [], {}, []
    for number, line in enumerate(lines):
        if line.startswith("| ") and not line.startswith("| " + HEADER[0] + " |"):
            cells = [c.strip().replace("\\|", "|") for c in re.split(r"(?<!\\)\|", line)[1:-1]]
            if len(cells) != len(HEADER):
                raise OverviewError("the overview's table row %d has %d cells, expected %d (%s): %s"
                                    % (len(table) + 1, len(cells), len(HEADER), ", ".join(HEADER), line))
            table.append(cells)
        elif " is a published run (" in line and not line.startswith("> "):
            published.setdefault(line.split(" is a published run (", 1)[0], []).append(line)
        elif line.startswith("> " + LOADED):
            loaded = line[len("> " + LOADED):].split(LOADED_TAIL)[0].split(", ")
    new_rows = {}
    for r in runs:
        new_rows.setdefault(r.name, []).append(row(r))
    rows = []
    for cells in table:
        if cells[0] not in names:
            rows.append(cells)
        elif cells[0] in new_rows:  # where the experiment's first row was
            rows.extend(new_rows.pop(cells[0]))
    for more in new_rows.values():  # experiments the report did not list
        rows.extend(more)
    for name in names:
        published.pop(name, None)
    for r in runs:
        if r.published is not None:
            published.setdefault(r.name, []).append(published_text(r, repo))
    loaded = [n for n in loaded if n and n not in names] + [r.name for r in runs if overloaded(r)]
    doc.heading(2, HEADING)
    t = Table(HEADER)
    for cells in rows:
        t.add(cells)
    doc.table(t)
    doc.paragraph(LOAD_TEXT)
    for name in dict.fromkeys(cells[0] for cells in rows):
        for text in published.get(name, []):
            doc.paragraph(text)
    if loaded:
        doc.note(LOADED + ", ".join(loaded) + LOADED_TAIL)
    if any("(dirty)" in cells[3] or cells[3].startswith("unknown") for cells in rows):
        doc.note(DIRTY_TEXT)
