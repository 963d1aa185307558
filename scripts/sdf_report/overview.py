"""The runs a report is made of: experiment, kind, run id, commit, machine, build, load, and
the regression check when the run records one."""

import os

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


def section(doc, runs, repo):
    doc.heading(2, "Runs")
    if not runs:
        doc.note("No runs found. Run a study first, e.g. `build/bin/run-experiment configs/ci_smoke.json`.")
        return
    table = Table(["experiment", "kind", "run", "commit", "CPU", "GPU", "build", "load (start/end)", "check"])
    for r in runs:
        cpu, gpu = machine(r)
        table.add([r.name, r.kind, r.run_id, commit(r), cpu, gpu, r.provenance["build"]["build_type"], load_text(r),
                   check_text(r)])
    doc.table(table)
    doc.paragraph("Load: the 1-minute load average when the run started and ended; timings from a machine whose load "
                  "exceeds its hardware threads are not representative. Check: the regression check against the "
                  "run's baseline, when the run was made with --check and records it.")
    published = [r for r in runs if r.published is not None]
    for r in published:
        doc.paragraph("%s is a published run (%s, scripts/publish-gpu-results)%s" % (
            r.name, source_text(r, repo), ": " + r.published["note"] if "note" in r.published else "."))
    loaded = [r.name for r in runs if overloaded(r)]
    if loaded:
        doc.note("Made on a loaded machine (load above its hardware threads): %s. Their times and speedups are "
                 "inflated or compressed by other work; errors and counts are unaffected." % ", ".join(loaded))
    if any(r.provenance["git"]["dirty"] for r in runs):
        doc.note("Runs marked dirty were made from a work tree with uncommitted changes (or without git: commit "
                 "\"unknown\"; a tree without .git records the commit passed in as SDF_SOURCE_COMMIT, \"(passed in)\").")
