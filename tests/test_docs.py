"""The documentation: README.md and docs/*.md.

- The site (MkDocs, ``mkdocs.yml``) builds with ``--strict``: any warning fails, broken links and
  anchors between pages included, and the API reference renders from the docstrings.
- Every relative link and image in README.md and docs/*.md points at a file of the checkout, and
  every ``#anchor`` at a heading of its page (by GitHub's rule and by MkDocs's).
- Every fenced ``bash``/``console`` command and every ``python`` block runs as written, one test per
  block (named by file and line), from a temporary folder outside the checkout, so commands that
  only work in a checkout or snippets that went stale fail here.

The markdown says what a block needs in an HTML comment on the line before its fence:

- ``<!-- not-run: reason -->``: not run here (installing, apt-get, the whole test suite, a
  server). Each such block is listed in ``NOT_RUN`` below: adding one is a conscious act.
- ``<!-- file: NAME -->``: the block (YAML, say) is written to NAME in the page's folder, for the
  commands after it.
- ``<!-- exit: N -->``: the block's (last) command is expected to exit with N.
- ``<!-- requires: chromium -->``: skipped where the program is not installed (except in CI).
- ``<!-- output -->`` before a ``text`` block: what the runnable block before it prints
  (compared with whitespace collapsed; ``...`` stands for anything).

A ``console`` block holds commands after ``$ `` and their output, compared the same way.

The blocks of one page run in order in one folder (a later block may use an earlier one's files);
a block run alone first runs the blocks before it on its page. Pages run two at a time.
"""

import json
import os
import re
import shutil
import subprocess
import sys
import threading
import unicodedata
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

import pytest
import yaml

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
# The repository's other top-level pages: not in the site and run nowhere, but their links are checked.
FRONT_PAGES = [ROOT / "CONTRIBUTING.md", ROOT / "CHANGELOG.md"]

# Blocks that are not run, by (page, first line): every one must carry a not-run comment, and every
# not-run comment must be listed here.
NOT_RUN = {
    ("README.md", "pip wheel --no-deps . -w dist && pip install dist/drake_traj-*.whl"),
    ("README.md", "python3 -m venv .venv && . .venv/bin/activate && pip install . && drake-traj run --out out"),
    ("README.md", "apt-get update && apt-get install -y chromium"),
    ("docs/getting-started.md", "python3 -m venv .venv && . .venv/bin/activate && pip install ."),
    ("docs/getting-started.md", "apt-get update && apt-get install -y chromium"),
    ("docs/benchmarks.md", "drake-traj bench --count 20 --out out/bench20"),
    ("docs/benchmarks.md", "drake-traj bench --suite soak --count 10000 --arms ur10e --scheduler tcp://host:8786 --out out/soak_ur10e"),
}
RUNNABLE = {"bash", "sh", "shell", "console", "python"}
TIMEOUT_S = 600


@dataclass
class Block:
    page: Path
    line: int  # of the opening fence, 1-based
    language: str
    text: str
    markers: dict = field(default_factory=dict)
    output: "Block | None" = None  # the text block after it marked <!-- output -->

    @property
    def name(self) -> str:
        return f"{self.page.relative_to(ROOT)}:{self.line}"

    @property
    def first_line(self) -> str:
        return next((line.strip() for line in self.text.splitlines() if line.strip()), "")


FENCE = re.compile(r"^(?P<indent> *)(?P<fence>`{3,}|~{3,})(?P<info>[^`]*)$")
MARKER = re.compile(r"^\s*<!--\s*(?P<key>[a-z-]+)\s*(?::\s*(?P<value>.*?))?\s*-->\s*$")


def parse_blocks(page: Path) -> list[Block]:
    """The fenced blocks of ``page``, each with the markers on the lines just before it."""
    lines = page.read_text(encoding="utf-8").splitlines()
    blocks, i = [], 0
    while i < len(lines):
        opening = FENCE.match(lines[i])
        if not opening:
            i += 1
            continue
        indent, fence = len(opening["indent"]), opening["fence"]
        body, j = [], i + 1
        while j < len(lines) and not (lines[j].strip().startswith(fence) and lines[j].strip().strip(fence[0]) == ""):
            body.append(lines[j][indent:] if lines[j][:indent].strip() == "" else lines[j])
            j += 1
        markers, k = {}, i - 1
        while k >= 0 and MARKER.match(lines[k]):
            match = MARKER.match(lines[k])
            markers[match["key"]] = match["value"] or ""
            k -= 1
        language = opening["info"].strip().split()[0] if opening["info"].strip() else ""
        blocks.append(Block(page, i + 1, language, "\n".join(body) + "\n", markers))
        i = j + 1
    runnable = None
    for block in blocks:
        if "output" in block.markers:
            assert runnable is not None, f"{block.name}: an output block with no runnable block before it"
            runnable.output = block
        elif block.language in RUNNABLE:
            runnable = block
    return blocks


ALL_BLOCKS = {page: parse_blocks(page) for page in PAGES}


def steps(page: Path) -> list[Block]:
    """What runs of a page, in order: runnable blocks and files to write."""
    return [b for b in ALL_BLOCKS[page] if "not-run" not in b.markers and "output" not in b.markers
            and (b.language in RUNNABLE or "file" in b.markers)]


RUN_BLOCKS = [b for page in PAGES for b in steps(page) if b.language in RUNNABLE]


# ---------------------------------------------------------------------------------------------
# running


def normalized(text: str) -> str:
    return " ".join(text.split())


# the progress a long command prints on stderr (a line after seconds of silence: on a busy machine,
# before the output a page shows) is not part of the page's output
PROGRESS_LINE = re.compile(r"^drake-traj (run|bench): .*\n?", flags=re.MULTILINE)


def matches(expected: str, actual: str) -> bool:
    pattern = ".*?".join(re.escape(part) for part in normalized(expected).split("..."))
    return re.fullmatch(pattern, normalized(PROGRESS_LINE.sub("", actual)), flags=re.DOTALL) is not None


def environment() -> dict:
    env = dict(os.environ)
    env["PATH"] = os.pathsep.join([str(Path(sys.executable).parent), env.get("PATH", "")])
    env["MPLBACKEND"] = "Agg"
    env.pop("PYTHONPATH", None)  # the installed package, as a user has it
    return env


def shell(command: str, folder: Path) -> subprocess.CompletedProcess:
    return subprocess.run(["bash", "-e", "-o", "pipefail", "-c", command], cwd=folder, env=environment(),
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, timeout=TIMEOUT_S)


def console_commands(text: str) -> list[tuple[str, str]]:
    """(command, expected output) pairs of a console block; continuation lines end with a backslash."""
    pairs, lines, i = [], text.splitlines(), 0
    while i < len(lines):
        if not lines[i].startswith("$ "):
            raise AssertionError(f"console block line without '$ ' before any command: {lines[i]!r}")
        command = lines[i][2:]
        while command.endswith("\\") and i + 1 < len(lines):
            i += 1
            command = command[:-1] + " " + lines[i].strip()
        i += 1
        output = []
        while i < len(lines) and not lines[i].startswith("$ "):
            output.append(lines[i])
            i += 1
        pairs.append((command, "\n".join(output)))
    return pairs


def check_exit(block: Block, process: subprocess.CompletedProcess, what: str, expected: int) -> None:
    assert process.returncode == expected, (
        f"{block.name}: {what} exited {process.returncode} (expected {expected}); its output:\n{process.stdout[-4000:]}")


def run_block(block: Block, folder: Path) -> None:
    if "file" in block.markers:
        (folder / block.markers["file"]).write_text(block.text, encoding="utf-8")
        return
    if "requires" in block.markers and shutil.which(block.markers["requires"]) is None and not os.environ.get("CI"):
        pytest.skip(f"{block.markers['requires']} is not installed")
    expected_exit = int(block.markers.get("exit", 0))
    if block.language == "console":
        pairs = console_commands(block.text)
        for index, (command, expected) in enumerate(pairs):
            process = shell(command, folder)
            check_exit(block, process, f"$ {command}", expected_exit if index == len(pairs) - 1 else 0)
            assert matches(expected, process.stdout), (
                f"{block.name}: $ {command}\nprinted:\n{process.stdout}\nthe page says:\n{expected}")
        return
    if block.language == "python":
        script = folder / f"block_{block.line}.py"
        script.write_text(block.text, encoding="utf-8")
        process = subprocess.run([sys.executable, script.name], cwd=folder, env=environment(), stdout=subprocess.PIPE,
                                 stderr=subprocess.PIPE, text=True, timeout=TIMEOUT_S)
        process.stdout += process.stderr if process.returncode else ""
    else:
        process = shell(block.text, folder)
    check_exit(block, process, "the block", expected_exit)
    if block.output is not None:
        assert matches(block.output.text, process.stdout), (
            f"{block.name}: printed:\n{process.stdout}\nthe page ({block.output.name}) says:\n{block.output.text}")


def cost(page: Path) -> int:
    """A rough estimate of a page's run time, to start the longest pages first."""
    text = "".join(block.text for block in steps(page))
    return 10 * text.count("drake-traj bench") + 3 * text.count("drake-traj run") + len(steps(page))


class PageRuns:
    """One folder per page, outside the checkout. The blocks of a page run in order, once, in a
    thread of their own; pages run side by side (``WORKERS`` at a time: the commands are separate
    processes), so the test of a block waits for its block's outcome."""

    WORKERS = 2

    def __init__(self, base: Path):
        self.base = base
        self.pool = ThreadPoolExecutor(max_workers=self.WORKERS)
        self.outcome: dict[str, Future] = {}
        self.started: set[Path] = set()
        self.lock = threading.Lock()

    def start(self, pages) -> None:
        """Run ``pages`` (the longest first), each block's outcome a future."""
        with self.lock:
            new = [page for page in pages if page not in self.started]
            self.started.update(new)
            for page in sorted(new, key=lambda page: -cost(page)):
                for block in steps(page):
                    self.outcome[block.name] = Future()
                self.pool.submit(self._run_page, page)

    def _run_page(self, page: Path) -> None:
        folder = self.base / page.stem
        folder.mkdir(exist_ok=True)
        assert ROOT not in folder.resolve().parents and folder.resolve() != ROOT
        failed = None
        for block in steps(page):
            future = self.outcome[block.name]
            if failed is not None:
                future.set_exception(AssertionError(
                    f"{block.name} needs {failed}, an earlier block of its page, which failed"))
                continue
            try:
                run_block(block, folder)
                future.set_result(None)
            except BaseException as error:  # pytest's skip and fail outcomes included
                future.set_exception(error)
                if not isinstance(error, pytest.skip.Exception):
                    failed = block.name

    def result(self, block: Block) -> None:
        self.start([block.page])
        self.outcome[block.name].result(timeout=TIMEOUT_S * len(steps(block.page)))


@pytest.fixture(scope="session")
def page_runs(tmp_path_factory, request) -> PageRuns:
    runs = PageRuns(tmp_path_factory.mktemp("docs_blocks"))
    selected = [item.callspec.params["block"] for item in request.session.items
                if getattr(item, "callspec", None) and isinstance(item.callspec.params.get("block"), Block)]
    runs.start(sorted({block.page for block in selected}))
    yield runs
    runs.pool.shutdown(wait=True, cancel_futures=True)


@pytest.mark.parametrize("block", RUN_BLOCKS, ids=[b.name for b in RUN_BLOCKS])
def test_block_runs_as_written(block, page_runs):
    page_runs.result(block)


# Numbers a page states about a run its own blocks make: (page, the statement with the number as its
# group, the run's metrics.json in the page's folder, the metric). The number must be the run's,
# rounded to the digits the page gives.
RUN_NUMBERS = [
    ("docs/free-motion.md", r"`duration_s` (\d+\.\d+) s", "out/free_motion_shelf/metrics.json", "duration_s"),
    ("docs/smooth_timing.md", r"\| `smooth_waypoints` \| (\d+\.\d+) s through", "out/smooth_waypoints/metrics.json",
     "duration_s"),
    ("docs/smooth_timing.md", r"\| `pajak_retimed` \| (\d+\.\d+) s against", "out/pajak_retimed/metrics.json", "duration_s"),
    ("docs/smooth_timing.md", r"max jerk (\d+\.\d+) rad/s³ against", "out/pajak_retimed/metrics.json", "max_jerk"),
]


@pytest.mark.parametrize("page, statement, metrics, key", RUN_NUMBERS, ids=[f"{row[0]}:{row[3]}" for row in RUN_NUMBERS])
def test_a_number_a_page_states_is_its_runs(page, statement, metrics, key, page_runs):
    path = ROOT / page
    stated = re.findall(statement, path.read_text(encoding="utf-8"))
    assert len(stated) == 1, f"{page}: {statement!r} found {len(stated)} times"
    for block in steps(path):
        page_runs.result(block)  # the page's blocks ran (a failing block fails here too)
    measured = json.loads((page_runs.base / path.stem / metrics).read_text(encoding="utf-8"))[key]
    digits = len(stated[0].partition(".")[2])
    assert f"{measured:.{digits}f}" == stated[0], f"{page} says {stated[0]}; the run's {key} is {measured}"


def test_the_blocks_not_run_are_the_listed_ones():
    marked = {(str(b.page.relative_to(ROOT)), b.first_line) for page in PAGES for b in ALL_BLOCKS[page]
              if "not-run" in b.markers}
    for page in PAGES:
        for block in ALL_BLOCKS[page]:
            if "not-run" in block.markers:
                assert block.markers["not-run"].strip(), f"{block.name}: not-run needs a reason"
    assert marked == NOT_RUN, f"not-run blocks in the pages: {sorted(marked)}; listed: {sorted(NOT_RUN)}"


def test_every_runnable_fence_has_a_known_language():
    """A fence without a language, or with one we do not run, holds no command by mistake."""
    for page in PAGES:
        for block in ALL_BLOCKS[page]:
            if block.language in {"", "sh", "shell"}:
                assert not re.search(r"^\s*(\$ )?(drake-traj|python3?|pip) ", block.text, flags=re.M), (
                    f"{block.name}: a command in a fence without a language (```bash, ```console)")
            assert block.language not in {"pycon", "bash-session", "shell-session"}, f"{block.name}: use ```console"


# ---------------------------------------------------------------------------------------------
# links


LINK = re.compile(r"!?\[(?:[^\[\]]|\[[^\]]*\])*\]\((?P<target><[^>]+>|[^)\s]+)(?:\s+\"[^\"]*\")?\)")
HEADING = re.compile(r"^(#{1,6})\s+(?P<title>.+?)\s*#*\s*$")


def github_slug(title: str) -> str:
    text = re.sub(r"[`*]|\[([^\]]*)\]\([^)]*\)", r"\1", title).strip().lower()
    return re.sub(r"[^\w\- ]", "", text).replace(" ", "-")


def mkdocs_slug(title: str) -> str:
    text = re.sub(r"[`*]|\[([^\]]*)\]\([^)]*\)", r"\1", title)
    text = unicodedata.normalize("NFKD", text).encode("ascii", "ignore").decode("ascii")
    text = re.sub(r"[^\w\s-]", "", text).strip().lower()
    return re.sub(r"[-\s]+", "-", text)


def anchors(page: Path) -> tuple[set, set]:
    github, mkdocs, fenced = set(), set(), False
    for line in page.read_text(encoding="utf-8").splitlines():
        if FENCE.match(line):
            fenced = not fenced
        heading = None if fenced else HEADING.match(line)
        if heading:
            github.add(github_slug(heading["title"]))
            mkdocs.add(mkdocs_slug(heading["title"]))
    return github, mkdocs


def links(page: Path):
    fenced = False
    for number, line in enumerate(page.read_text(encoding="utf-8").splitlines(), 1):
        if FENCE.match(line):
            fenced = not fenced
            continue
        if fenced:
            continue
        for match in LINK.finditer(re.sub(r"`[^`]*`", "", line)):
            yield number, match["target"].strip("<>")


@pytest.mark.parametrize("page", PAGES + FRONT_PAGES, ids=[str(p.relative_to(ROOT)) for p in PAGES + FRONT_PAGES])
def test_relative_links_point_at_files_and_headings(page):
    broken = []
    for number, target in links(page):
        if re.match(r"^[a-z][a-z0-9+.-]*:", target):  # http:, https:, mailto:
            assert not target.startswith("file:"), f"{page.name}:{number}: {target}"
            continue
        path, _, anchor = target.partition("#")
        destination = (page.parent / path).resolve() if path else page
        if ROOT not in destination.parents and destination != ROOT:
            broken.append(f"line {number}: {target} leaves the repository")
        elif not destination.exists():
            broken.append(f"line {number}: {target} does not exist")
        elif page.parent == ROOT / "docs" and ROOT / "docs" not in destination.parents and destination.suffix == ".md":
            broken.append(f"line {number}: {target}: a page outside docs/ is not in the site")
        elif anchor:
            github, mkdocs = anchors(destination)
            if anchor not in github or anchor not in mkdocs:
                broken.append(f"line {number}: {target}: no heading with that anchor on GitHub and in the site")
    assert not broken, f"{page.relative_to(ROOT)}:\n" + "\n".join(broken)


# ---------------------------------------------------------------------------------------------
# the site


def test_the_site_builds_with_warnings_as_errors(tmp_path):
    if not os.environ.get("CI"):
        pytest.importorskip("mkdocstrings", reason="the documentation tools: pip install '.[test]'")
    process = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--config-file",
                              str(ROOT / "mkdocs.yml"), "--site-dir", str(tmp_path / "site")],
                             cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                             timeout=TIMEOUT_S)
    assert process.returncode == 0, process.stdout[-6000:]
    assert "WARNING" not in process.stdout, process.stdout[-6000:]
    site = tmp_path / "site"
    api = (site / "api" / "index.html").read_text(encoding="utf-8")
    for name in ("simulate", "load_scenario", "SimulationResult", "PajakConfig", "time_path", "DrakeTrajError"):
        assert name in api, f"the API reference lacks {name}"
    for page in (ROOT / "docs").glob("*.md"):
        built = site / ("index.html" if page.stem == "index" else f"{page.stem}/index.html")
        assert built.exists(), f"{page.name} is not in the site"


# ---------------------------------------------------------------------------------------------
# the front door: licence and citation


def test_the_licence_and_the_citation_say_what_pyproject_says():
    import tomllib

    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    assert project["license"]["text"] == "BSD-3-Clause"
    assert (ROOT / "LICENSE").read_text(encoding="utf-8").startswith("BSD 3-Clause License")
    citation = yaml.safe_load((ROOT / "CITATION.cff").read_text(encoding="utf-8"))
    assert citation["cff-version"] == "1.2.0" and citation["title"] == project["name"]
    assert citation["version"] == project["version"] and citation["license"] == project["license"]["text"]


def test_the_citations_references_are_the_papers_as_docs_papers_md_cites_them():
    papers = normalized((ROOT / "docs" / "papers.md").read_text(encoding="utf-8"))
    references = yaml.safe_load((ROOT / "CITATION.cff").read_text(encoding="utf-8"))["references"]
    assert len(references) == 4
    for reference in references:
        assert normalized(reference["title"]) in papers, reference["title"]
        for author in reference["authors"]:
            assert f"{author['given-names']} {author['family-names']}" in papers, author
        if "journal" in reference:  # volume(issue), first–last page, as the table of names gives them
            assert f"{reference['volume']}({reference['issue']}), {reference['start']}–{reference['end']}" in papers
            assert str(reference["year"]) in papers
        if "doi" in reference:
            assert f"DOI [{reference['doi']}](https://doi.org/{reference['doi']})" in papers
