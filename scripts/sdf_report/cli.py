"""scripts/make-report: the command line, and the report put together from the sections."""

import argparse
import datetime
import os
import sys

from . import analytic, filters, overview, peers, plots, reconstruction, sampling, scaling, speedup, user_wait
from . import runs as run_loader
from . import schema as run_schema
from .document import Document

REPO = run_schema.REPO
PUBLISHED = os.path.join(REPO, "results", "report")
LOCAL = os.path.join(REPO, "results", "report-local")

USAGE = """Makes the report of stored runs: report.md and a self-contained index.html (plots and
image grids embedded), with the plots as PNG beside them.

Reads the runs under --results (every <experiment>/<run-id>/ holding manifest.json and
metrics.json, and the published GPU runs gpu/*.json) and reports the latest run of each
experiment, or the RUN paths given (run directories or published files), all of them.
Every run is validated against harness/schema/run_schema.json: a missing or mistyped key
is an error naming the file and the key (--skip-invalid leaves such runs out instead).

The report goes to results/report-local/ (git-ignored) unless --output names another
directory; --publish writes the committed report, results/report/. docs/harness.md
("Reports") describes the sections.
"""

SECTIONS = (sampling.section, speedup.section, analytic.section, reconstruction.section, filters.section, peers.section)


def parse_args(argv):
    ap = argparse.ArgumentParser(prog="make-report", description=USAGE, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("runs", nargs="*", metavar="RUN", help="run directories or published run files (default: the latest "
                                                            "run of every experiment under --results)")
    ap.add_argument("--results", default=os.path.join(REPO, "results"), help="results directory to scan (default: %(default)s)")
    ap.add_argument("--output", help="where the report goes (default: %s)" % os.path.relpath(LOCAL, REPO))
    ap.add_argument("--publish", action="store_true", help="write the committed report, %s" % os.path.relpath(PUBLISHED, REPO))
    ap.add_argument("--skip-invalid", action="store_true", help="leave out runs that do not match the schema (with a "
                                                                 "warning) instead of failing")
    args = ap.parse_args(argv)
    if args.publish and args.output and os.path.abspath(args.output) != PUBLISHED:
        ap.error("--publish writes %s; do not combine it with --output %s" % (PUBLISHED, args.output))
    args.output = os.path.abspath(PUBLISHED if args.publish else args.output or LOCAL)
    return args


def prepare_output(out_dir):
    """Creates out_dir, or empties a previous report's plots from it. A non-empty directory
    that holds no report (report.md and index.html) is refused: its files are not ours."""
    if os.path.isdir(out_dir) and os.listdir(out_dir):
        is_report = all(os.path.isfile(os.path.join(out_dir, f)) for f in ("report.md", "index.html"))
        if not is_report:
            raise SystemExit("make-report: error: %s is not empty and holds no report (report.md, index.html); "
                             "choose another --output" % out_dir)
        plots.remove_old_plots(out_dir)
    os.makedirs(out_dir, exist_ok=True)


def describe_source(args):
    if args.runs:
        return "the given runs"
    results = os.path.abspath(args.results)
    return os.path.relpath(results, REPO) if results.startswith(REPO + os.sep) else results


def build(doc, runs, args, skipped):
    published = args.output == PUBLISHED
    doc.heading(1, "Sampling and reconstruction of distance fields on CC and BCC lattices: results")
    doc.paragraph("Generated %s by scripts/make-report from %d run(s) under %s." % (
        datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"), len(runs), describe_source(args)))
    if not published:
        doc.note("A local report of the runs on this machine. The published report is results/report/ "
                 "(scripts/make-report --publish).")
    for message in skipped:
        doc.note("Left out (--skip-invalid): " + message.replace("\n", " "))
    overview.section(doc, runs, REPO)
    for section in SECTIONS:
        section(doc, runs)
    scaling.section(doc, args.results)  # scripts/scaling-run's JSON lines, not run-experiment runs
    user_wait.section(doc, args.results)  # scripts/user-wait's records, likewise


def main(argv=None):
    args = parse_args(sys.argv[1:] if argv is None else argv)
    try:
        schema = run_schema.load_schema()
        runs, skipped = run_loader.collect(args.results, [os.path.abspath(p) for p in args.runs], schema,
                                           skip_invalid=args.skip_invalid,
                                           warn=lambda text: print("make-report: warning: " + text, file=sys.stderr))
    except (run_schema.RunFileError, run_schema.SchemaFileError) as e:
        print("make-report: error: %s" % e, file=sys.stderr)
        if isinstance(e, run_schema.RunFileError):
            print("make-report: (--skip-invalid leaves such runs out of the report)", file=sys.stderr)
        return 1
    prepare_output(args.output)
    doc = Document(args.output)
    try:
        build(doc, runs, args, skipped)
    except user_wait.UserWaitFileError as e:
        print("make-report: error: %s" % e, file=sys.stderr)
        return 1
    doc.write("sdf_lattices results")
    print("report: %s and index.html (%d runs)" % (os.path.join(args.output, "report.md"), len(runs)))
    return 0
