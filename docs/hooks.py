"""MkDocs hook (``mkdocs.yml``): the figures live in ``examples/figures/``, where the scripts that
draw them write them. The pages link them as ``../examples/figures/NAME.png``, which is right on
GitHub and in a checkout; the site gets them as ``figures/NAME.png``."""

from pathlib import Path

from mkdocs.structure.files import File

FIGURES = Path(__file__).resolve().parents[1] / "examples" / "figures"


def on_files(files, config):
    for figure in sorted(FIGURES.glob("*.png")):
        files.append(File(f"figures/{figure.name}", src_dir=str(FIGURES.parent), dest_dir=config["site_dir"],
                          use_directory_urls=config["use_directory_urls"]))
    return files


def on_page_markdown(markdown, page, config, files):
    return markdown.replace("](../examples/figures/", "](figures/")


# The docstrings write units after values in brackets ("[x, y, z] [m]", "[q; q̇] [rad, rad/s]"),
# which Markdown reads as a reference link "[text][label]". A griffe extension (mkdocs.yml,
# handlers.python.options.extensions) escapes the second bracket outside code spans.

import re

import griffe

_UNIT_BRACKET = re.compile(r"\]( ?)\[")


def escape_unit_brackets(text: str) -> str:
    parts = re.split(r"(``.*?``|`[^`]*`)", text, flags=re.S)
    return "".join(part if part.startswith("`") else _UNIT_BRACKET.sub(r"]\1\\[", part) for part in parts)


class EscapeUnitBrackets(griffe.Extension):
    def on_instance(self, *, obj, **kwargs) -> None:
        if obj.docstring is not None:
            obj.docstring.value = escape_unit_brackets(obj.docstring.value)
