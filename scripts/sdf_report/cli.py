"""scripts/make-report: the command line, and the report put together from the sections."""

import argparse
import datetime
import os
import sys

from . import analytic, filters, overview, peers, plots, reconstruction, sampling, scaling, speedup, user_wait
from . import runs as run_loader
from . import schema as run_schema
from .document import Document, write_text_atomically

REPO = run_schema.REPO
PUBLISHED = os.path.join(REPO, "results", "report")
LOCAL = os.path.join(REPO, "results", "report-local")

USAGE = """Makes the report of stored runs: report.md and a self-contained index.html (plots and
image grids embedded), with the plots as PNG beside them.

Reads the runs under --results (every <experiment>/<run-id>/ holding manifest.json and
metrics.json, and the published GPU runs gpu/*.json) and reports the latest run of each
experiment, or the RUN paths given (run directories or published files), all of them.
A RUN that is a scripts/user-wait record (user_wait.json) goes to the section "Where the user
waits" instead of the records under --results (the latest per machine of those given).
--only-section user-wait rewrites that section alone in an existing report (--output or
--publish), keeping the rest as it is (for a published report whose runs are not all on disk);
--only-section peers likewise rewrites the peers section from the peers runs given (run
directories or published files), or else the latest run of each peers experiment under
--results, and says so in it; the overview at the top then lists those runs in place of the
peers runs it listed (its other entries stay those of the last full report).
Every run is validated against harness/schema/run_schema.json: a missing or mistyped key
is an error naming the file and the key (--skip-invalid leaves such runs out instead).

The report goes to results/report-local/ (git-ignored) unless --output names another
directory; --publish writes the committed report, results/report/. docs/harness.md
("Reports") describes the sections.
"""

SECTIONS = (sampling.section, speedup.section, analytic.section, reconstruction.section, filters.section, peers.section)
# The sections --only-section can rewrite alone, by their headings.
SECTION_HEADINGS = {"user-wait": user_wait.HEADING, "peers": peers.HEADING}


def parse_args(argv):
    ap = argparse.ArgumentParser(prog="make-report", description=USAGE, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("runs", nargs="*", metavar="RUN", help="run directories or published run files (default: the latest "
                                                            "run of every experiment under --results)")
    ap.add_argument("--results", default=os.path.join(REPO, "results"), help="results directory to scan (default: %(default)s)")
    ap.add_argument("--output", help="where the report goes (default: %s)" % os.path.relpath(LOCAL, REPO))
    ap.add_argument("--publish", action="store_true", help="write the committed report, %s" % os.path.relpath(PUBLISHED, REPO))
    ap.add_argument("--skip-invalid", action="store_true", help="leave out runs that do not match the schema (with a "
                                                                 "warning) instead of failing")
    ap.add_argument("--only-section", choices=sorted(SECTION_HEADINGS), help="rewrite only this section of the "
                                                                              "existing report in the output directory")
    args = ap.parse_args(argv)
    args.user_wait_files = [os.path.abspath(p) for p in args.runs if user_wait.is_user_wait_file(p)]
    args.runs = [p for p in args.runs if not user_wait.is_user_wait_file(p)]
    if args.only_section == "user-wait" and args.runs:
        ap.error("--only-section user-wait reads no experiment runs; give only user_wait.json records, or none")
    if args.only_section == "peers" and args.user_wait_files:
        ap.error("--only-section peers reads no user_wait.json records; give peers runs, or none")
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
    user_wait.section(doc, args.results, args.user_wait_files)  # scripts/user-wait's records, likewise


def rewrite_section(args):
    """--only-section: the section rendered anew and put in place of the old one (or after the
    last section) in the existing report.md and index.html; the rest is kept."""
    paths = [os.path.join(args.output, name) for name in ("report.md", "index.html")]
    if not all(os.path.isfile(p) for p in paths):
        raise SystemExit("make-report: error: --only-section needs an existing report in %s (report.md, index.html)"
                         % args.output)
    doc = Document(args.output)
    if args.only_section == "user-wait":
        user_wait.section(doc, args.results, args.user_wait_files)
    else:
        runs, _ = run_loader.collect(args.results, [os.path.abspath(p) for p in args.runs], run_schema.load_schema(),
                                     skip_invalid=args.skip_invalid,
                                     warn=lambda text: print("make-report: warning: " + text, file=sys.stderr))
        runs = [r for r in runs if r.kind == "peers"]
        if not runs:
            raise SystemExit("make-report: error: --only-section peers: no peers run %s"
                             % ("among the runs given" if args.runs else "under " + args.results))
        peers.section(doc, runs)
        doc.paragraph("This section was rewritten alone on %s (scripts/make-report --only-section peers) from the "
                      "runs %s, and with it their entries in the overview at the top; the other entries there are "
                      "those of the last full report." % (
                          datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
                          ", ".join("%s %s" % (r.name, r.run_id) for r in runs)))
    heading = SECTION_HEADINGS[args.only_section]
    with open(paths[0], encoding="utf-8") as f:
        markdown = f.read()
    with open(paths[1], encoding="utf-8") as f:
        page = f.read()
    if args.only_section == "peers":
        runs_doc = Document(args.output)
        overview.rewritten(runs_doc, markdown, runs, REPO)
        runs_html = runs_doc.html("").split("<body>", 1)[1].rsplit("</body>", 1)[0].strip("\n")
        markdown = _replace(markdown, "\n## " + overview.HEADING, "\n## ", runs_doc.markdown().rstrip("\n"))
        page = _replace(page, "\n<h2>" + overview.HEADING, "\n<h2>", runs_html, end="\n</body>", sep="\n")
    new_html = doc.html("").split("<body>", 1)[1].rsplit("</body>", 1)[0].strip("\n")
    write_text_atomically(paths[0], _replace(markdown, "\n## " + heading, "\n## ", doc.markdown().rstrip("\n")))
    write_text_atomically(paths[1], _replace(page, "\n<h2>" + heading, "\n<h2>", new_html, end="\n</body>", sep="\n"))


def _replace(text, start, next_start, new, end=None, sep="\n\n"):
    """text with the part from `start` to the next `next_start` (or `end`, or the end of the
    text) replaced by new; without `start`, new goes before `end` (or at the end). Blocks are
    joined by sep, so that rewriting a section twice gives the same text."""
    stop = len(text) if end is None else text.rindex(end)
    begin = text.find(start)
    if begin < 0:
        begin = stop
    following = text.find(next_start, begin + len(start))
    finish = following if 0 <= following < stop and begin < stop else stop
    tail = text[finish:].lstrip("\n")
    return text[:begin].rstrip("\n") + sep + new + (sep + tail if tail else "\n")


def main(argv=None):
    args = parse_args(sys.argv[1:] if argv is None else argv)
    if args.only_section:
        try:
            rewrite_section(args)
        except (user_wait.UserWaitFileError, run_schema.RunFileError, run_schema.SchemaFileError) as e:
            print("make-report: error: %s" % e, file=sys.stderr)
            return 1
        except overview.OverviewError as e:
            print("make-report: error: %s: %s (make the whole report again instead: scripts/make-report%s)"
                  % (os.path.join(args.output, "report.md"), e, " --publish" if args.publish else ""), file=sys.stderr)
            return 1
        print("report: the section '%s' rewritten in %s" % (SECTION_HEADINGS[args.only_section], args.output))
        return 0
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
