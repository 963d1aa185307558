"""The run schema (harness/schema/run_schema.json and the $defs files it lists under
harness/schema/defs/) and a validator for the subset of JSON Schema it uses.

The schema states, per experiment kind, the keys of metrics.json and the manifest keys the
report reads, with their types. The report validates every run it reads against it, and
the contract test (tests/python/test_run_schema_contract.py) validates what run-experiment
really writes, strictly: there a key the schema does not declare is an error too, so the
C++ side and the report cannot drift apart unnoticed.

Keywords understood: type, properties, required, additionalProperties, items, enum, const,
if/then/else, $ref (to "#/$defs/<name>") and the annotations description, title, $comment,
$schema, $id, $defs. Any other keyword is an error in the schema's files, so that no rule is
silently ignored. Strict mode: an object whose schema lists "properties" and says nothing
about "additionalProperties" may hold no other key (the report itself reads leniently:
keys it does not know are ignored).

load_schema() joins the files into one document: the top file's "$defs_files" names the
$defs files, in order, and is consumed there; every $ref stays "#/$defs/<name>".
"""

import json
import os

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCHEMA_NAME = "harness/schema/run_schema.json"
SCHEMA_PATH = os.path.join(REPO, *SCHEMA_NAME.split("/"))
DEFS_FILES = "$defs_files"  # the top document's list of its $defs files, consumed by load_schema()

_ANNOTATIONS = {"description", "title", "$comment", "$schema", "$id", "$defs"}
_KEYWORDS = {"type", "properties", "required", "additionalProperties", "items", "enum", "const", "if", "then", "else",
             "$ref"} | _ANNOTATIONS
_TYPES = {"object", "array", "string", "number", "integer", "boolean", "null"}


class RunFileError(Exception):
    """A run's file is missing, unreadable, or does not match the schema. The message names
    the file, the key (a path such as rows[2].backends[0].seconds_median) and what was
    expected."""


class SchemaFileError(Exception):
    """A file of the run schema is malformed (a bug in the repository, not in a run)."""


def _read_json(path, what):
    def no_duplicates(pairs):
        # json.load would keep the last of two equal keys: a def (or rule) silently lost.
        seen = set()
        for key, _ in pairs:
            if key in seen:
                raise SchemaFileError("%s: key \"%s\" appears twice in one object" % (path, key))
            seen.add(key)
        return dict(pairs)
    try:
        with open(path) as f:
            return json.load(f, object_pairs_hook=no_duplicates)
    except (OSError, ValueError) as e:
        raise SchemaFileError("%s: cannot read %s: %s" % (path, what, e)) from None


def schema_files(path=SCHEMA_PATH):
    """The files of the run schema: the top document, then the $defs files it lists under
    "$defs_files" (paths relative to its folder), in that order."""
    return [path] + [part for part, _ in _defs_parts(_read_json(path, "the run schema"), path)]


def _defs_parts(schema, path):
    """(file, its $defs) per entry of the top document's "$defs_files"."""
    listed = schema.get(DEFS_FILES, [])
    if not isinstance(listed, list) or not all(isinstance(name, str) and name for name in listed):
        raise SchemaFileError("%s: key \"%s\": expected a list of file names (relative to %s)"
                              % (path, DEFS_FILES, os.path.dirname(path)))
    parts = []
    for i, name in enumerate(listed):
        part_path = os.path.join(os.path.dirname(path), *name.split("/"))
        if name in listed[:i]:
            raise SchemaFileError("%s: key \"%s\" lists %s twice" % (path, DEFS_FILES, name))
        part = _read_json(part_path, "a $defs file of the run schema (listed in %s)" % path)
        # Only definitions: a rule placed beside them would be dropped unseen.
        if not isinstance(part, dict) or not isinstance(part.get("$defs"), dict) or set(part) - {"description", "$defs"}:
            got = _show(sorted(part) if isinstance(part, dict) else part)
            raise SchemaFileError("%s: expected an object of \"$defs\" (an object of named definitions) and an optional "
                                  "\"description\", got %s" % (part_path, got))
        parts.append((part_path, part["$defs"]))
    return parts


def load_schema(path=SCHEMA_PATH):
    """The run schema as one document: the top file's "$defs" joined with those of the files
    its "$defs_files" lists (that key consumed), so every $ref stays "#/$defs/<name>"."""
    schema = _read_json(path, "the run schema")
    if not isinstance(schema, dict) or not isinstance(schema.get("manifest"), dict) \
            or not isinstance(schema.get("metrics"), dict):
        raise SchemaFileError("%s: expected the keys \"manifest\" and \"metrics\" (by kind)" % path)
    parts = _defs_parts(schema, path)
    schema.pop(DEFS_FILES, None)
    defs = schema.get("$defs", {})
    if not isinstance(defs, dict):
        raise SchemaFileError("%s: key \"$defs\": expected an object of named definitions" % path)
    where = dict.fromkeys(defs, path)
    for part_path, part_defs in parts:
        for name, definition in part_defs.items():
            if name in where:
                raise SchemaFileError("run schema: $defs \"%s\" is defined in both %s and %s"
                                      % (name, where[name], part_path))
            where[name] = part_path
            defs[name] = definition
    schema["$defs"] = defs
    return schema


def lattice_types(schema=None):
    """The lattice kinds' names, as the schema's $defs.lattice_type lists them: the names of
    the lattice table kLatticeKinds (kernels/lattice/lattice_kinds.h) in its order, the
    Cartesian kind first (tests/python_module/test_lattice_kinds.py checks they match)."""
    return list((schema or load_schema())["$defs"]["lattice_type"]["enum"])


def metrics_schema(schema, kind):
    """The schema of metrics.json of one experiment kind (its single-run or sweep form)."""
    return schema["metrics"].get(kind)


def known_kinds(schema):
    return sorted(schema["metrics"])


def type_name(value):
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "boolean"
    if isinstance(value, int):
        return "integer"
    if isinstance(value, float):
        return "number"
    if isinstance(value, str):
        return "string"
    if isinstance(value, list):
        return "array"
    if isinstance(value, dict):
        return "object"
    return type(value).__name__


def _matches_type(value, expected):
    actual = type_name(value)
    return actual == expected or (expected == "number" and actual == "integer")


def _show(value):
    text = json.dumps(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _join(path, key):
    if isinstance(key, int):
        return "%s[%d]" % (path, key)
    return key if not path else "%s.%s" % (path, key)


class Validator:
    """Validates JSON values against one schema document; errors are collected, not raised,
    so that a run with several problems shows all of them at once."""

    def __init__(self, root, strict=False):
        self.root = root
        self.strict = strict
        self.errors = []

    def check(self, value, schema, path=""):
        self._check(value, schema, path)
        return self.errors

    def _resolve(self, ref):
        prefix = "#/$defs/"
        if not ref.startswith(prefix) or ref[len(prefix):] not in self.root.get("$defs", {}):
            raise SchemaFileError("run schema: unknown $ref %r" % ref)
        return self.root["$defs"][ref[len(prefix):]]

    def _fail(self, path, text):
        self.errors.append("key '%s': %s" % (path or "(top level)", text))

    def _check(self, value, schema, path, declared=None):
        """`declared`: the properties of the enclosing schema when `schema` is its then/else
        branch (so that a conditionally required key is described by its declaration)."""
        unknown = set(schema) - _KEYWORDS
        if unknown:
            raise SchemaFileError("run schema: unknown keyword(s) %s at %s" % (", ".join(sorted(unknown)), path or "top"))
        if "$ref" in schema:
            self._check(value, self._resolve(schema["$ref"]), path)
        if "type" in schema and not self._type_ok(value, schema["type"], path):
            return  # nothing else is meaningful for a value of the wrong type
        if "const" in schema and value != schema["const"]:
            self._fail(path, "expected %s, got %s" % (_show(schema["const"]), _show(value)))
        if "enum" in schema and value not in schema["enum"]:
            self._fail(path, "expected one of %s, got %s" % (", ".join(_show(v) for v in schema["enum"]), _show(value)))
        if isinstance(value, dict):
            self._check_object(value, schema, path, declared or {})
        if isinstance(value, list) and "items" in schema:
            for i, item in enumerate(value):
                self._check(item, schema["items"], _join(path, i))
        if "if" in schema:
            probe = Validator(self.root, strict=False)
            probe._check(value, schema["if"], path)
            branch = schema.get("then") if not probe.errors else schema.get("else")
            if branch is not None:
                self._check(value, branch, path, dict(declared or {}, **schema.get("properties", {})))

    def _type_ok(self, value, expected, path):
        allowed = expected if isinstance(expected, list) else [expected]
        for t in allowed:
            if t not in _TYPES:
                raise SchemaFileError("run schema: unknown type %r at %s" % (t, path or "top"))
        if any(_matches_type(value, t) for t in allowed):
            return True
        self._fail(path, "expected %s, got %s %s" % (" or ".join(allowed), type_name(value), _show(value)))
        return False

    def _check_object(self, value, schema, path, declared):
        for key in schema.get("required", []):
            if key not in value:
                declaration = schema.get("properties", {}).get(key, declared.get(key))
                self._fail(_join(path, key), "missing (expected %s)" % _describe(declaration))
        props = schema.get("properties", {})
        extra = schema.get("additionalProperties")
        for key, item in value.items():
            if key in props:
                self._check(item, props[key], _join(path, key))
            elif isinstance(extra, dict):
                self._check(item, extra, _join(path, key))
            elif extra is False or (self.strict and extra is None and "properties" in schema):
                self._fail(_join(path, key), "not declared in the run schema (%s)" % SCHEMA_NAME)


def _describe(schema):
    if not schema:
        return "a value"
    if "$ref" in schema:
        return schema["$ref"].split("/")[-1]
    t = schema.get("type", "a value")
    text = " or ".join(t) if isinstance(t, list) else t
    if "description" in schema:
        text += ": " + schema["description"]
    return text


def validate_file(value, part_schema, root, file_path, strict=False):
    """Raises RunFileError listing every problem of `value` (the parsed `file_path`) against
    `part_schema`, a part of the schema document `root` (whose $defs it may use)."""
    errors = Validator(root, strict).check(value, part_schema)
    if errors:
        raise RunFileError("%s: does not match the run schema (%s):\n  %s" % (file_path, SCHEMA_NAME, "\n  ".join(errors)))
