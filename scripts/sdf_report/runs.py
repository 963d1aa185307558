"""Finding and loading stored runs, each validated against the run schema.

A run is a directory results/<experiment>/<run-id>/ holding manifest.json and metrics.json
(harness/runner), or a published GPU run results/gpu/<date>-<gpu>.json (one file holding
both, scripts/publish-gpu-results). A sweep's metrics hold one entry per sweep point under
"points"; Run.points gives every run as such a list (one entry when it is no sweep).
"""

import json
import os

from . import schema as run_schema

PUBLISHED_FORMAT = "sdf-gpu-results"


class Point:
    """One sweep point of a run (or the whole run): its name, metrics and directory."""

    def __init__(self, name, metrics, directory):
        self.name = name
        self.metrics = metrics
        self.dir = directory


class Run:
    def __init__(self, path, manifest, metrics, published=None):
        self.path = path            # the run directory, or the published file
        self.manifest = manifest
        self.metrics = metrics
        # For a published run: the file's other keys ("source_commit", "note"); else None.
        self.published = published

    @property
    def name(self):
        return self.manifest["name"]

    @property
    def kind(self):
        return self.manifest["kind"]

    @property
    def run_id(self):
        return self.manifest["run_id"]

    @property
    def provenance(self):
        return self.manifest["provenance"]

    @property
    def is_sweep(self):
        return "points" in self.metrics

    @property
    def points(self):
        base = self.path if self.published is None else os.path.dirname(self.path)
        if not self.is_sweep:
            return [Point(self.name, self.metrics, base)]
        return [Point(p["name"], p["metrics"], os.path.join(base, p["name"])) for p in self.metrics["points"]]

    def sort_key(self):
        return (self.manifest["finished"], self.run_id)


def _read_json(path):
    try:
        with open(path, encoding="utf-8") as f:
            return json.load(f)
    except FileNotFoundError:
        raise run_schema.RunFileError("%s: missing" % path) from None
    except (OSError, ValueError) as e:
        raise run_schema.RunFileError("%s: cannot read it as JSON: %s" % (path, e)) from None


def validate(manifest, metrics, manifest_where, metrics_where, schema, strict=False):
    """Validates a manifest and its metrics (the metrics by the manifest's kind)."""
    run_schema.validate_file(manifest, schema["manifest"], schema, manifest_where, strict)
    kind = manifest["kind"]
    part = run_schema.metrics_schema(schema, kind)
    if part is None:  # the manifest schema's enum of kinds already says so; kept for safety
        raise run_schema.RunFileError("%s: key 'kind': no metrics schema for kind %r (known: %s)"
                                      % (manifest_where, kind, ", ".join(run_schema.known_kinds(schema))))
    run_schema.validate_file(metrics, part, schema, metrics_where, strict)


def load_run_dir(path, schema, strict=False):
    manifest_path = os.path.join(path, "manifest.json")
    metrics_path = os.path.join(path, "metrics.json")
    manifest = _read_json(manifest_path)
    metrics = _read_json(metrics_path)
    validate(manifest, metrics, manifest_path, metrics_path, schema, strict)
    return Run(path, manifest, metrics)


def load_published(path, schema):
    data = _read_json(path)
    if not isinstance(data, dict) or data.get("format") != PUBLISHED_FORMAT or data.get("version") != 1:
        # (.get: this decides whether the file is a published run at all)
        raise run_schema.RunFileError("%s: key 'format': expected a published run (\"format\": %r, \"version\": 1)"
                                      % (path, PUBLISHED_FORMAT))
    for key in ("manifest", "metrics"):
        if not isinstance(data.get(key), dict):
            raise run_schema.RunFileError("%s: key '%s': missing or not an object" % (path, key))
    for key in ("source_commit", "note"):
        if key in data and not isinstance(data[key], str):
            raise run_schema.RunFileError("%s: key '%s': expected a string, got %s" % (path, key, run_schema.type_name(data[key])))
    validate(data["manifest"], data["metrics"], path + " (manifest)", path + " (metrics)", schema)
    info = {key: data[key] for key in ("source_commit", "note") if key in data}
    return Run(path, data["manifest"], data["metrics"], published=info)


def load_any(path, schema):
    """A run directory or a published run file."""
    if os.path.isfile(path) and path.endswith(".json"):
        return load_published(path, schema)
    if not os.path.isdir(path):
        raise run_schema.RunFileError("%s: neither a run directory nor a published run file" % path)
    return load_run_dir(path, schema)


def candidate_paths(results_dir):
    """Every run under results_dir: <name>/<run-id>/ with a manifest.json (hidden staging
    directories skipped) and the published runs gpu/*.json."""
    found = []
    if not os.path.isdir(results_dir):
        return found
    for name in sorted(os.listdir(results_dir)):
        base = os.path.join(results_dir, name)
        if name.startswith(".") or not os.path.isdir(base):
            continue
        for entry in sorted(os.listdir(base)):
            path = os.path.join(base, entry)
            if entry.startswith("."):
                continue
            if os.path.isfile(os.path.join(path, "manifest.json")):
                found.append(path)
            elif name == "gpu" and entry.endswith(".json") and os.path.isfile(path):
                found.append(path)
    return found


def latest_per_experiment(runs):
    """The latest run (by finish time, then run id) of each experiment name, sorted by name."""
    latest = {}
    for r in runs:
        if r.name not in latest or r.sort_key() > latest[r.name].sort_key():
            latest[r.name] = r
    return [latest[k] for k in sorted(latest)]


def collect(results_dir, explicit, schema, skip_invalid=False, warn=None):
    """The runs to report: the explicit paths (all of them, in order), or the latest run of
    each experiment under results_dir. An invalid run is an error, or with skip_invalid a
    warning (passed to `warn`) and left out. Returns (runs, skipped messages)."""
    paths = explicit or candidate_paths(results_dir)
    runs, skipped = [], []
    for path in paths:
        try:
            runs.append(load_any(path, schema))
        except run_schema.RunFileError as e:
            if not skip_invalid:
                raise
            skipped.append(str(e))
            if warn:
                warn("skipping an invalid run: %s" % e)
    return (runs if explicit else latest_per_experiment(runs)), skipped
