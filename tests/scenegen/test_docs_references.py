"""What README.md and docs/*.md name exists: every ``scenegen VERB --flag`` shown is a
verb and a flag of the parser (and every whole command in a code block parses), every
``scenegen.…`` / ``trackers.…`` name resolves, every relative link and its anchor exists
inside the project, every quoted section reference names a section of its file, and a
reference that says "below" or "above" points the right way.

Mechanical checks of drift between the docs and the code; fast (no command is run).
"""

from __future__ import annotations

import argparse
import importlib
import re
import shlex
from pathlib import Path

from scenegen.cli import _parser

ROOT = Path(__file__).resolve().parents[2]
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]


def _line(text: str, pos: int) -> int:
    return text[:pos].count("\n") + 1


def _verbs() -> dict[str, argparse.ArgumentParser]:
    sub = next(a for a in _parser()._actions if isinstance(a, argparse._SubParsersAction))
    return dict(sub.choices)


def _options(parser: argparse.ArgumentParser) -> set[str]:
    found = {"--debug"}  # taken anywhere on the line
    for action in parser._actions:
        found.update(action.option_strings)
        if isinstance(action, argparse._SubParsersAction):  # fixtures verify|regen
            for child in action.choices.values():
                found |= _options(child)
    return found


def _commands() -> list[tuple[str, int, bool, str]]:
    """(file, line, whole command in a code block?, command) for every ``scenegen VERB``
    in a console or indented block (continuation lines joined) or in inline code."""
    verbs = "|".join(sorted(_verbs(), key=len, reverse=True))
    found = []
    for path in DOCS:
        text = path.read_text(encoding="utf-8")
        lines = text.splitlines()
        i = 0
        while i < len(lines):
            raw = lines[i]
            cmd = raw.strip().removeprefix("$ ")
            start = i
            if re.match(rf"scenegen ({verbs})\b", cmd) and (
                raw.startswith("    ") or raw.lstrip().startswith("$ ")
            ):
                while cmd.endswith("\\") and i + 1 < len(lines):
                    i += 1
                    cmd = cmd[:-1].rstrip() + " " + lines[i].strip()
                found.append((path.name, start + 1, True, re.sub(r"\s+#.*$", "", cmd)))
            i += 1
        for m in re.finditer(rf"`(scenegen (?:{verbs})\b[^`]*)`", text):
            found.append((path.name, _line(text, m.start()), False, m.group(1)))
    return found


def test_the_docs_show_commands():
    commands = _commands()
    assert len(commands) > 50 and sum(whole for _, _, whole, _ in commands) > 20


def test_every_flag_shown_is_an_option_of_its_verb():
    verbs = _verbs()
    bad = []
    for name, line, _, cmd in _commands():
        options = _options(verbs[cmd.split()[1]])
        for flag in re.findall(r"(?<![\w-])(--?[A-Za-z][\w-]*)", cmd):
            if flag.split("=")[0] not in options:
                bad.append(f"{name}:{line}: {flag} in {cmd!r}")
    assert not bad, "\n".join(bad)


def test_every_whole_command_in_a_code_block_parses():
    parser = _parser()
    bad = []
    for name, line, whole, cmd in _commands():
        if not whole or re.search(r"…|\.\.\.|\[|\|", cmd):  # a synopsis, not a command
            continue
        try:
            parser.parse_args(shlex.split(cmd)[1:])
        except SystemExit:
            bad.append(f"{name}:{line}: {cmd!r}")
    assert not bad, "\n".join(bad)


def _resolve(name: str) -> object:
    parts = name.split(".")
    for i in range(len(parts), 0, -1):
        try:
            obj: object = importlib.import_module(".".join(parts[:i]))
        except ImportError:
            continue
        for part in parts[i:]:
            obj = getattr(obj, part)
        return obj
    raise ImportError(name)


def test_every_python_name_in_code_spans_resolves():
    names: dict[str, str] = {}
    for path in DOCS:
        text = path.read_text(encoding="utf-8")
        for m in re.finditer(r"`([^`\n]+)`", text):
            for name in re.findall(r"\b((?:scenegen|trackers)(?:\.[A-Za-z_]\w*)+)", m.group(1)):
                names.setdefault(name, f"{path.name}:{_line(text, m.start())}")
    assert len(names) > 30
    bad = []
    for name, where in sorted(names.items()):
        try:
            _resolve(name)
        except (ImportError, AttributeError) as err:
            bad.append(f"{where}: {name} ({err})")
    assert not bad, "\n".join(bad)


def _slug(heading: str) -> str:
    """GitHub's anchor of a heading."""
    text = re.sub(r"[^\w\- ]", "", heading.replace("`", "").strip().lower())
    return text.replace(" ", "-")


def _leads(path: Path) -> list[tuple[int, str]]:
    """(line, title) of every heading, bold paragraph or item lead, and ``Word:`` lead."""
    out = []
    in_code = False
    for i, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
        if line.startswith("```"):
            in_code = not in_code
        if in_code:
            continue
        m = (
            re.match(r"^#+\s+(.*)$", line)
            or re.match(r"^(?:- )?\*\*(.+?)\*\*", line)
            or re.match(r"^([A-Z][\w ]{2,40}):", line)
        )
        if m:
            out.append((i, m.group(1).replace("`", "").strip()))
    return out


def _names_section(leads: list[tuple[int, str]], title: str) -> list[int]:
    title = title.replace("`", "")
    return [line for line, lead in leads if lead.startswith(title) or title in lead]


def test_links_and_anchors_exist_inside_the_project():
    bad = []
    for path in DOCS:
        text = path.read_text(encoding="utf-8")
        for m in re.finditer(r"\]\(([^)\s]+)\)", text):
            link = m.group(1)
            if re.match(r"[a-z]+:", link):
                continue
            where = f"{path.name}:{_line(text, m.start())}: {link}"
            file, _, anchor = link.partition("#")
            target = (path.parent / file).resolve() if file else path
            if not target.is_relative_to(ROOT):
                bad.append(f"{where} points outside the project")
            elif not target.exists():
                bad.append(f"{where}: no such file")
            elif anchor and target.suffix == ".md":
                slugs = {_slug(t) for line, t in _leads(target)}
                if anchor not in slugs:
                    bad.append(f"{where}: no such section")
    assert not bad, "\n".join(bad)


def test_quoted_section_references_name_a_section():
    """``docs/experiments.md "Scenes and runs"`` (or ``("A", "B")``), in the docs and in
    the sources' docstrings and comments."""
    sources = [*DOCS, *sorted(p for d in ("scenegen", "trackers", "tools", "tests") for p in
                                (ROOT / d).rglob("*.py"))]  # fmt: skip
    bad = []
    checked = 0
    for path in sources:
        text = path.read_text(encoding="utf-8")
        for m in re.finditer(r"(docs/[\w-]+\.md),?\s+\(?((?:\"[^\"\n]+\"(?:,\s*)?)+)", text):
            leads = _leads(ROOT / m.group(1))
            for title in re.findall(r"\"([^\"\n]+)\"", m.group(2)):
                checked += 1
                if not _names_section(leads, title):
                    where = f"{path.relative_to(ROOT)}:{_line(text, m.start())}"
                    bad.append(f"{where}: no section {title!r} in {m.group(1)}")
    assert checked > 10 and not bad, "\n".join(bad)


def test_see_names_a_section_of_the_docs():
    """``see "Title"`` without a file: a section of README.md or of a page of docs/."""
    leads = [lead for path in DOCS for lead in _leads(path)]
    bad = []
    for path in DOCS:
        text = path.read_text(encoding="utf-8")
        for m in re.finditer(r"\b[Ss]ee ((?:\"[^\"\n]+\"(?:,? (?:and |or )?)?)+)", text):
            for title in re.findall(r"\"([^\"\n]+)\"", m.group(1)):
                if not _names_section(leads, title):
                    bad.append(f"{path.name}:{_line(text, m.start())}: no section {title!r}")
    assert not bad, "\n".join(bad)


def test_below_and_above_point_the_right_way():
    bad = []
    checked = 0
    for path in DOCS:
        text = path.read_text(encoding="utf-8")
        leads = _leads(path)
        for m in re.finditer(
            r"[\"*](?P<a>[^\"*\n]{3,80})[\"*],? (?P<da>below|above)"
            r"|(?P<db>below|above),? [\"*](?P<b>[^\"*\n]{3,80})[\"*]",
            text,
        ):
            title, way = (m["a"], m["da"]) if m["a"] else (m["b"], m["db"])
            line = _line(text, m.start())
            places = [at for at in _names_section(leads, title) if at != line]
            if not places:
                continue  # not a section of this file (a quoted phrase)
            checked += 1
            if not any((at > line) == (way == "below") for at in places):
                bad.append(f"{path.name}:{line}: {title!r} is not {way} (line {places[0]})")
    assert checked >= 5 and not bad, "\n".join(bad)
