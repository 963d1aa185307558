"""The run schema's validator: missing and mistyped keys are errors naming the file and the
key; strict mode rejects undeclared keys; the schema's files use only keywords it knows. Its
loader: the $defs files the top document lists are joined into one document, every file
under harness/schema/ is listed and every $ref resolves; a name defined twice, a missing or
malformed file is an error naming the files."""
import glob
import json
import os

import pytest

import fake_runs
from sdf_report import runs
from sdf_report import schema as run_schema
from sdf_report.schema import RunFileError, SchemaFileError, Validator, validate_file


def errors_of(value, part, root, strict=False):
    return Validator(root, strict).check(value, part)


def test_the_schema_file_loads_and_covers_every_kind(schema):
    assert run_schema.known_kinds(schema) == ["analytic", "peers", "reconstruction", "sampling", "speedup"]
    assert schema["manifest"]["properties"]["kind"]["enum"] == list(schema["metrics"])


def test_every_keyword_of_the_schema_file_is_understood(schema):
    # Walk every sub-schema: the validator raises SchemaFileError on a keyword it would ignore.
    def walk(node, where):
        if isinstance(node, dict):
            unknown = set(node) - run_schema._KEYWORDS
            in_properties = where.endswith("properties") or where.endswith("$defs") or where == "metrics"
            if not in_properties:
                assert not unknown, "%s: %s" % (where, unknown)
            for key, value in node.items():
                walk(value, where + "/" + key)
        elif isinstance(node, list):
            for i, value in enumerate(node):
                walk(value, "%s[%d]" % (where, i))
    for part in ("manifest", "metrics", "$defs"):
        walk(schema[part], part)


def test_every_schema_file_is_listed_and_every_ref_resolves(schema):
    # A file under harness/schema/ that "$defs_files" does not list would be ignored unseen.
    folder = os.path.dirname(run_schema.SCHEMA_PATH)
    files = run_schema.schema_files()
    stray = sorted(set(glob.glob(os.path.join(folder, "**", "*.json"), recursive=True)) - set(files))
    assert not stray, "not listed under \"$defs_files\" of %s: %s" % (run_schema.SCHEMA_NAME, ", ".join(stray))
    for path in files:
        with open(path) as f:
            assert len(f.readlines()) < 600, "%s: over the repository's 600 lines a file" % path
    refs = []

    def walk(node, where):
        if isinstance(node, dict):
            if isinstance(node.get("$ref"), str):
                refs.append((where, node["$ref"]))
            for key, value in node.items():
                walk(value, where + "/" + key)
        elif isinstance(node, list):
            for i, value in enumerate(node):
                walk(value, "%s[%d]" % (where, i))
    walk(schema, "")
    assert len(refs) > 40
    for where, ref in refs:
        assert ref.startswith("#/$defs/") and ref[len("#/$defs/"):] in schema["$defs"], "%s: $ref %s" % (where, ref)


def test_missing_key_names_the_file_and_the_key_path(schema):
    metrics = fake_runs.speedup_metrics()
    del metrics["rows"][1]["backends"][0]["seconds_median"]
    with pytest.raises(RunFileError) as e:
        runs.validate(fake_runs.manifest("sp", "speedup"), metrics, "/r/sp/1/manifest.json", "/r/sp/1/metrics.json", schema)
    text = str(e.value)
    assert text.startswith("/r/sp/1/metrics.json: does not match the run schema (harness/schema/run_schema.json)")
    assert "key 'rows[1].backends[0].seconds_median': missing (expected number" in text


def test_mistyped_key_names_the_type_seen_and_expected(schema):
    metrics = fake_runs.reconstruction_metrics()
    metrics["probes"]["h_ref"] = "0.5"
    manifest = fake_runs.manifest("dragon", "reconstruction")
    manifest["provenance"]["git"]["dirty"] = "no"
    with pytest.raises(RunFileError) as e:
        runs.validate(manifest, metrics, "m.json", "metrics.json", schema)
    assert "m.json: does not match" in str(e.value)
    assert "key 'provenance.git.dirty': expected boolean, got string \"no\"" in str(e.value)
    with pytest.raises(RunFileError) as e:
        runs.validate(fake_runs.manifest("dragon", "reconstruction"), metrics, "m.json", "metrics.json", schema)
    assert "key 'probes.h_ref': expected number, got string \"0.5\"" in str(e.value)


def test_all_problems_of_a_file_are_listed_at_once(schema):
    metrics = fake_runs.analytic_metrics()
    del metrics["table_4_1"]["thesis"]
    metrics["convergence"]["curves"][0]["lattice_type"] = "fcc"
    with pytest.raises(RunFileError) as e:
        runs.validate(fake_runs.manifest("ml", "analytic"), metrics, "m", "metrics.json", schema)
    assert "key 'table_4_1.thesis': missing" in str(e.value)
    assert "key 'convergence.curves[0].lattice_type': expected one of \"cc\", \"bcc\", got \"fcc\"" in str(e.value)


def test_conditional_keys_speedup_backend_and_peers_row(schema):
    metrics = fake_runs.speedup_metrics()
    # An unavailable backend needs no times; an "ok" one does.
    assert not errors_of(metrics, schema["metrics"]["speedup"], schema)
    metrics["rows"][0]["backends"][2]["status"] = "ok"
    errors = errors_of(metrics, schema["metrics"]["speedup"], schema)
    assert "key 'rows[0].backends[2].total_seconds_median': missing (expected number: end to end, transfers included: " \
           "speedups are ratios of these)" in errors
    peers = fake_runs.peers_metrics()
    del peers["rows"][1]["status"]
    errors = errors_of(peers, schema["metrics"]["peers"], schema)
    assert any(e.startswith("key 'rows[1].query_seconds': missing") for e in errors)


def test_unknown_kind_is_an_error_naming_the_manifest_key(schema):
    with pytest.raises(RunFileError) as e:
        runs.validate(fake_runs.manifest("x", "nonsense"), {}, "x/manifest.json", "x/metrics.json", schema)
    assert "x/manifest.json" in str(e.value)
    assert "key 'kind': expected one of \"sampling\", \"speedup\", \"reconstruction\", \"analytic\", \"peers\", " \
           "got \"nonsense\"" in str(e.value)


def test_optional_check_object_is_typed_when_present(schema):
    manifest = fake_runs.manifest("x", "sampling", check={"baseline": "b.json", "passed": "yes", "ok": 1, "failed": 0,
                                                           "not_comparable": 0, "missing": 0, "added": 0})
    with pytest.raises(RunFileError) as e:
        validate_file(manifest, schema["manifest"], schema, "manifest.json")
    assert "key 'check.passed': expected boolean, got string \"yes\"" in str(e.value)
    del manifest["check"]
    validate_file(manifest, schema["manifest"], schema, "manifest.json", strict=True)


def test_strict_mode_rejects_undeclared_keys_lenient_mode_ignores_them(schema):
    metrics = fake_runs.sampling_metrics()
    metrics["fields"][0]["new_key"] = 1
    part = schema["metrics"]["sampling"]
    assert not errors_of(metrics, part, schema)
    assert errors_of(metrics, part, schema, strict=True) == [
        "key 'fields[0].new_key': not declared in the run schema (harness/schema/run_schema.json)"]


def test_open_objects_accept_any_key_even_strictly(schema):
    metrics = fake_runs.reconstruction_metrics(render=True)
    metrics["render"]["views"]["front"]["camera"]["anything"] = [1, 2]
    assert not errors_of(metrics, schema["metrics"]["reconstruction"], schema, strict=True)


def test_integer_is_a_number_but_not_the_reverse():
    root = {"$defs": {}}
    assert not errors_of(3, {"type": "number"}, root)
    assert errors_of(3.0, {"type": "integer"}, root) == ["key '(top level)': expected integer, got number 3.0"]
    assert errors_of(True, {"type": "integer"}, root) == ["key '(top level)': expected integer, got boolean true"]


def test_schema_file_errors_are_not_blamed_on_runs(tmp_path):
    root = {"$defs": {}}
    with pytest.raises(SchemaFileError):
        errors_of({}, {"type": "object", "minProperties": 1}, root)
    with pytest.raises(SchemaFileError):
        errors_of({}, {"$ref": "#/$defs/missing"}, root)
    bad = tmp_path / "schema.json"
    bad.write_text(json.dumps({"manifest": {}}))
    with pytest.raises(SchemaFileError) as e:
        run_schema.load_schema(str(bad))
    assert "\"metrics\"" in str(e.value)


def write_schema(folder, defs_files, parts, defs=None):
    """A top document listing `defs_files` (and holding `defs`), and the files of `parts`
    ({relative name: text}); returns the top document's path."""
    top = {"manifest": {"$ref": "#/$defs/m"}, "metrics": {"k": {"$ref": "#/$defs/k"}}, "$defs_files": defs_files}
    if defs is not None:
        top["$defs"] = defs
    for name, text in parts.items():
        (folder / name).parent.mkdir(parents=True, exist_ok=True)
        (folder / name).write_text(text)
    (folder / "top.json").write_text(json.dumps(top))
    return str(folder / "top.json")


def test_defs_files_are_joined_into_one_document(tmp_path):
    path = write_schema(tmp_path, ["defs/a.json", "defs/b.json"], {
        "defs/a.json": json.dumps({"description": "a",
                                   "$defs": {"m": {"type": "object", "properties": {"x": {"$ref": "#/$defs/x"}}}}}),
        "defs/b.json": json.dumps({"$defs": {"k": {"type": "object"}, "x": {"type": "integer"}}})},
        defs={"top": {"type": "string"}})
    schema = run_schema.load_schema(path)
    assert "$defs_files" not in schema
    assert list(schema["$defs"]) == ["top", "m", "k", "x"]  # files in their listed order
    assert errors_of({"x": "1"}, schema["manifest"], schema) == ["key 'x': expected integer, got string \"1\""]
    assert run_schema.schema_files(path) == [path, str(tmp_path / "defs" / "a.json"), str(tmp_path / "defs" / "b.json")]


def test_a_def_in_two_files_is_an_error_naming_both(tmp_path):
    path = write_schema(tmp_path, ["a.json", "b.json"], {"a.json": json.dumps({"$defs": {"m": {}, "k": {}}}),
                                                         "b.json": json.dumps({"$defs": {"k": {}}})})
    with pytest.raises(SchemaFileError) as e:
        run_schema.load_schema(path)
    assert str(e.value) == "run schema: $defs \"k\" is defined in both %s and %s" % (tmp_path / "a.json",
                                                                                    tmp_path / "b.json")
    path = write_schema(tmp_path, ["a.json"], {}, defs={"m": {}})
    with pytest.raises(SchemaFileError) as e:
        run_schema.load_schema(path)
    assert str(e.value) == "run schema: $defs \"m\" is defined in both %s and %s" % (path, tmp_path / "a.json")
    # Within one file too: json.load alone would keep the second silently.
    path = write_schema(tmp_path, ["a.json"], {"a.json": '{"$defs": {"m": {}, "k": {}, "m": {"type": "string"}}}'})
    with pytest.raises(SchemaFileError) as e:
        run_schema.load_schema(path)
    assert str(e.value) == "%s: key \"m\" appears twice in one object" % (tmp_path / "a.json")


@pytest.mark.parametrize("text, expected", [
    (None, "cannot read a $defs file of the run schema"),
    ('{"$defs": {', "cannot read a $defs file of the run schema"),
    ('[]', "expected an object of \"$defs\""),
    ('{"$defs": []}', "expected an object of \"$defs\""),
    ('{"$defs": {}, "k": {"type": "object"}}', "expected an object of \"$defs\" (an object of named definitions) and an "
                                                "optional \"description\", got [\"$defs\", \"k\"]"),
])
def test_a_missing_or_malformed_defs_file_is_an_error_naming_it(tmp_path, text, expected):
    path = write_schema(tmp_path, ["defs/a.json"], {} if text is None else {"defs/a.json": text})
    with pytest.raises(SchemaFileError) as e:
        run_schema.load_schema(path)
    assert str(e.value).startswith(str(tmp_path / "defs" / "a.json") + ": ")
    assert expected in str(e.value)


@pytest.mark.parametrize("listed, expected", [
    ("defs/a.json", "key \"$defs_files\": expected a list of file names"),
    (["a.json", 3], "key \"$defs_files\": expected a list of file names"),
    (["a.json", "a.json"], "key \"$defs_files\" lists a.json twice"),
])
def test_a_malformed_defs_files_list_is_an_error_naming_the_top_file(tmp_path, listed, expected):
    path = write_schema(tmp_path, listed, {"a.json": json.dumps({"$defs": {"m": {}, "k": {}}})})
    with pytest.raises(SchemaFileError) as e:
        run_schema.load_schema(path)
    assert str(e.value).startswith(path + ": " + expected)
