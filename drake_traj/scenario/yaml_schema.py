"""Strict reading of scenario YAML, before pydrake's ``yaml_load_typed`` builds the objects.

Every problem is one :class:`ScenarioError` naming the file, the line and column, the field's
path inside the document (``planner.velocity_limit[2]``), what was expected and what was found:
YAML syntax errors, duplicate keys (the YAML spec forbids them; loaders keep the last one
silently), Python object tags, unknown keys, and values of the wrong kind (text where a number is
expected, a number where a list is expected, ...). Types come from the dataclass annotations of
the schema (and the ``__fields__`` of pydrake's config classes), so there is one schema, the
dataclasses.
"""

import dataclasses
import re
import typing
from pathlib import Path

import numpy as np
import yaml
from pydrake.common.schema import Transform

from drake_traj.errors import DrakeTrajError, Field, did_you_mean, field_text

__all__ = ["ScenarioError", "checked_document"]

_INT, _FLOAT, _BOOL, _STR, _NULL = (f"tag:yaml.org,2002:{name}" for name in ("int", "float", "bool", "str", "null"))
_YAML12_FLOAT = re.compile(r"[-+]?(\.\d+|\d+(\.\d*)?)([eE][-+]?\d+)?")
_OPAQUE = (Transform,)  # types whose YAML form pydrake checks itself
_FOUND = {_INT: "an integer", _FLOAT: "a number", _BOOL: "true/false", _STR: "text", _NULL: "nothing (null)"}


class ScenarioError(DrakeTrajError):
    """A scenario file is malformed: names the file, the place and the field."""


class _Loader(yaml.SafeLoader):
    """SafeLoader whose mappings refuse duplicate keys (merge keys ``<<`` still merge)."""


def _where(path: Path, node) -> str:
    return f"{path}, line {node.start_mark.line + 1}, column {node.start_mark.column + 1}"


def _describe(node) -> str:
    if isinstance(node, yaml.MappingNode):
        return f"a mapping with keys {[key.value for key, _ in node.value]}"
    if isinstance(node, yaml.SequenceNode):
        return f"a list of {len(node.value)} entries"
    kind = _FOUND.get(node.tag, f"a value tagged {node.tag}")
    return f"{kind} {node.value!r}" if node.tag != _NULL else kind


def _fields(schema) -> dict:
    """{field name: type} of a dataclass or of a pydrake config class (``__fields__``)."""
    if dataclasses.is_dataclass(schema):
        hints = typing.get_type_hints(schema)
        return {item.name: hints[item.name] for item in dataclasses.fields(schema)}
    return {item.name: item.type for item in schema.__fields__}


def _is_record(schema) -> bool:
    return isinstance(schema, type) and (dataclasses.is_dataclass(schema) or hasattr(schema, "__fields__"))


class Marks(dict):
    """{field path: YAML node} of a checked scenario, for locating later value errors, and
    ``replaced``: {field path: (the key node, the merged value node it replaces)} for each mapping
    a merge key (``<<: *anchor``) brought in and the document's own key replaced whole (YAML's
    merge is shallow), to explain an error inside it."""

    def __init__(self, *args):
        super().__init__(*args)
        self.replaced: dict[Field, tuple] = {}


def _replacement_note(marks: Marks, field: Field) -> str:
    """Where ``field`` lies in a mapping that replaced a merged one: what happened and what to do."""
    for length in range(len(field), 0, -1):
        if field[:length] in marks.replaced:
            key, merged = marks.replaced[field[:length]]
            name = field_text(field[:length])
            tag = f" {merged.tag}" if merged.tag.startswith("!") else ""
            return (f" (note: {name} at line {key.start_mark.line + 1} replaces the whole {name}{tag} merged from line "
                    f"{merged.start_mark.line + 1}: a YAML merge (<<) is shallow, so only the fields given at line "
                    f"{key.start_mark.line + 1} count; give the tag and every field there, or merge the anchor's {name} "
                    f"into it with an anchor of its own)")
    return ""


class _Checker:
    def __init__(self, path: Path, loader: _Loader):
        self.path = path
        self.loader = loader
        self.marks = Marks()  # field path -> node, for value errors found later

    def fail(self, node, field: Field, message: str) -> typing.NoReturn:
        where = f"{_where(self.path, node)}: " if node is not None else f"{self.path}: "
        note = _replacement_note(self.marks, field)
        raise ScenarioError(f"{where}{field_text(field) + ': ' if field else ''}{message}{note}", field=field)

    def mapping_items(self, node, field: Field):
        """The (key, value) nodes of a mapping, merge keys applied (a key of the mapping's own
        replaces a merged one whole: recorded in ``marks.replaced`` where both are mappings),
        duplicate keys refused."""
        seen = {}
        for key, _ in node.value:
            if not isinstance(key, yaml.ScalarNode):
                self.fail(key, field, f"a key must be a plain name, found {_describe(key)}")
            if key.tag == "tag:yaml.org,2002:merge":
                continue
            if key.value in seen:
                self.fail(key, field + (key.value,),
                          f"duplicate key (first at line {seen[key.value].start_mark.line + 1}); "
                          "each key may appear once")
            seen[key.value] = key
        try:
            self.loader.flatten_mapping(node)
        except yaml.MarkedYAMLError as error:  # e.g. << merging a list or a scalar
            raise ScenarioError(f"{self.path}: {field_text(field) + ': ' if field else ''}{_mark_message(error)}",
                                field=field) from None
        last = {key.value: (key, value) for key, value in node.value}  # flattened: merged first, own last
        for key, value in node.value:
            own_key, own_value = last[key.value]
            if own_key is not key and isinstance(value, yaml.MappingNode) and isinstance(own_value, yaml.MappingNode):
                self.marks.replaced[field + (key.value,)] = (own_key, value)
        return [(key, value) for key, value in node.value if last[key.value][0] is key]

    def check(self, node, schema, field: Field) -> None:
        self.marks[field] = node
        if node.tag.startswith("tag:yaml.org,2002:python/"):
            self.fail(node, field, f"the tag {node.tag.split(':', 2)[-1]!r} is not allowed: scenario files hold data, "
                                   "not Python objects")
        origin = typing.get_origin(schema)
        if origin is typing.Union and type(None) in typing.get_args(schema):  # Optional[X] (pydrake's directives)
            (inner,) = [option for option in typing.get_args(schema) if option is not type(None)]
            return None if node.tag == _NULL else self.check(node, inner, field)
        if origin is typing.Union:
            return self.check_union(node, typing.get_args(schema), field)
        if origin is dict:
            if not isinstance(node, yaml.MappingNode):
                self.fail(node, field, f"expected a mapping, found {_describe(node)}")
            _, item = typing.get_args(schema)
            for key, value in self.mapping_items(node, field):
                self.check(value, item, field + (key.value,))
            return None
        if schema is np.ndarray:  # a number or a list of numbers, e.g. a directive's joint positions
            for child in node.value if isinstance(node, yaml.SequenceNode) else [node]:
                self.check(child, float, field)
            return None
        if schema in _OPAQUE:  # pydrake's own variants (a Transform's !Rpy rotation): pydrake reads them
            return None
        if origin is list:
            if not isinstance(node, yaml.SequenceNode):
                self.fail(node, field, f"expected a list, found {_describe(node)}")
            (item,) = typing.get_args(schema)
            for index, child in enumerate(node.value):
                self.check(child, item, field + (index,))
            return None
        if _is_record(schema):
            return self.check_record(node, schema, field)
        expected = {float: ("a number", (_INT, _FLOAT)), int: ("an integer", (_INT,)), bool: ("true or false", (_BOOL,)),
                    str: ("text", (_STR,))}
        if schema in expected:
            description, tags = expected[schema]
            # PyYAML reads YAML 1.1, where 1e6 and 1.0e6 are text; pydrake's reader (and YAML 1.2)
            # reads them as numbers, so an unquoted one counts as a number here too
            yaml12_number = (schema is float and isinstance(node, yaml.ScalarNode) and node.tag == _STR
                             and node.style is None and _YAML12_FLOAT.fullmatch(node.value) is not None)
            if not yaml12_number and (not isinstance(node, yaml.ScalarNode) or node.tag not in tags):
                self.fail(node, field, f"expected {description}, found {_describe(node)}")
            return None
        raise TypeError(f"no YAML check for the type {schema!r} of {field_text(field)}")  # a schema we did not foresee

    def check_union(self, node, options, field: Field) -> None:
        """A union of records chosen by a YAML tag (``planner: !PajakConfig``), one of which may be
        text (``robot: ur10e`` or ``robot: !DhArm {...}``): pydrake reads an untagged value as
        the first type; or a union of text, numbers and true/false (a xacro argument)."""
        scalars = {str: (_STR,), int: (_INT,), float: (_INT, _FLOAT), bool: (_BOOL,)}
        if all(option in scalars for option in options):
            if not isinstance(node, yaml.ScalarNode) or node.tag not in {tag for o in options for tag in scalars[o]}:
                self.fail(node, field, f"expected text, a number or true/false, found {_describe(node)}")
            return None
        text = str in options
        names = {option.__name__: option for option in options if option is not str}
        if text and isinstance(node, yaml.ScalarNode) and not node.tag.startswith("!"):
            return self.check(node, str, field)
        if not isinstance(node, yaml.MappingNode):
            either = "a name or " if text else ""
            self.fail(node, field, f"expected {either}a mapping tagged with one of !{', !'.join(names)}, found {_describe(node)}")
        tag = node.tag[1:] if node.tag.startswith("!") and not node.tag.startswith("!!") else None
        if tag is None and options[0] is str:
            self.fail(node, field, f"a mapping needs a tag naming its type, one of !{', !'.join(names)} (e.g. "
                                   f"{field_text(field)}: !{next(iter(names))})")
        if tag is None and len(names) == 1:  # untagged, one record (robot.inertia: {density: 1800}): that one
            return self.check_record(node, options[0], field)
        if tag is None:  # untagged: pydrake reads the first type
            keys = {key.value for key, _ in node.value}
            if not keys <= set(_fields(options[0])) | {"<<"}:
                self.fail(node, field, f"needs a tag naming its type, one of !{', !'.join(names)} "
                                       f"(e.g. {field_text(field)}: !{options[1].__name__}); without one it is read as "
                                       f"{options[0].__name__}, which has no {sorted(keys - set(_fields(options[0])))}")
            return self.check_record(node, options[0], field)
        if tag not in names:
            hint = did_you_mean(tag, names, tags=True)
            self.fail(node, field, f"unknown type !{tag}; expected one of !{', !'.join(names)}{f' ({hint})' if hint else ''}")
        return self.check_record(node, names[tag], field)

    def check_record(self, node, schema, field: Field) -> None:
        if not isinstance(node, yaml.MappingNode):
            self.fail(node, field, f"expected a mapping of {schema.__name__}'s fields, found {_describe(node)}")
        if node.tag.startswith("!") and not node.tag.startswith("!!") and node.tag[1:] != schema.__name__:
            self.fail(node, field, f"the tag {node.tag} does not belong here: this field is a {schema.__name__} "
                                   "(tags choose a planner's type under planner:); remove the tag")
        fields = _fields(schema)
        for key, value in self.mapping_items(node, field):
            name = field + (key.value,)
            if key.value not in fields:
                hint = did_you_mean(key.value, fields)
                self.fail(key, name, f"unknown field{f' ({hint})' if hint else ''}; {schema.__name__} has {sorted(fields)}")
            self.check(value, fields[key.value], name)


def _mark_message(error: yaml.MarkedYAMLError) -> str:
    mark = error.problem_mark or error.context_mark
    where = f"line {mark.line + 1}, column {mark.column + 1}: " if mark else ""
    return f"{where}{error.problem or error.context}"


def checked_document(path: Path, schema, variant_keys=None) -> tuple[object, dict, typing.Callable]:
    """Parse the scenario file ``path`` strictly.

    Returns (top-level mapping node, {variant name: node} (empty for a file of one scenario),
    ``check(node, field_prefix) -> marks``) where ``check`` validates a scenario node against
    ``schema`` and returns {field path: node} for locating later value errors.
    Raises :class:`ScenarioError`.
    """
    try:
        raw = path.read_bytes()
    except OSError as error:
        raise ScenarioError(f"{path}: cannot be read: {error.strerror}") from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as error:
        raise ScenarioError(f"{path} is not a text (UTF-8) file: byte {raw[error.start]:#04x} at offset "
                            f"{error.start} cannot be decoded") from None
    try:
        loader = _Loader(text)
        root = loader.get_single_node()
        loader.dispose()
    except yaml.MarkedYAMLError as error:
        raise ScenarioError(f"{path}: YAML syntax error at {_mark_message(error)}") from None
    except yaml.reader.ReaderError as error:
        raise ScenarioError(f"{path}: the character {chr(error.character)!r} at offset {error.position} is not "
                            "allowed in a YAML file") from None
    except yaml.YAMLError as error:
        raise ScenarioError(f"{path}: YAML error: {error}") from None
    except RecursionError:
        raise ScenarioError(f"{path}: the document is nested too deeply to be a scenario") from None
    checker = _Checker(path, loader)
    if root is None:
        checker.fail(None, (), "the file is empty; a scenario needs at least a planner (see diagrams/)")
    if not isinstance(root, yaml.MappingNode):
        checker.fail(root, (), f"a scenario file must be a mapping of fields (or of named variants), found {_describe(root)}")
    fields = _fields(schema)
    for key, _ in root.value:
        if not isinstance(key, yaml.ScalarNode):
            checker.fail(key, (), f"a key must be a plain name, found {_describe(key)}")
    keys = [key.value for key, _ in root.value]
    variants = {}
    if not set(keys) & set(fields):  # a file of variants: top-level keys name them
        for key, value in checker.mapping_items(root, ()):
            if not key.value.startswith("_"):
                variants[key.value] = value

    def check(node, prefix: Field = ()) -> Marks:
        checker.marks = Marks()
        try:
            checker.check_record(node, schema, prefix)
        except RecursionError:
            raise ScenarioError(f"{path}: the document is nested too deeply to be a scenario") from None
        return checker.marks

    return root, variants, check


def locate(marks: dict, path: Path, field: Field, message: str) -> str:
    """``message`` prefixed with the file and the line of ``field`` (a path such as
    ``("planner", "waypoints", 1)``) where the marks hold it, else of the nearest field that
    holds it (the list it indexes, the mapping a missing field belongs in); with a note where
    the field lies in a mapping that replaced a merged one (:class:`Marks`)."""
    field = tuple(field)
    node = next((marks[field[:length]] for length in range(len(field), 0, -1) if field[:length] in marks), None)
    where = _where(path, node) if node is not None else str(path)
    note = _replacement_note(marks, field) if isinstance(marks, Marks) else ""
    return f"{where}: {message}{note}"
