"""README.md and docs/*.md stay true to the tree, as they are when the test runs: every
`scripts/orbed ...` command line in their code blocks parses with the CLI's parser
(orbed_cli.main.parse_args, which looks at nothing on disk), and every relative Markdown link
resolves to a file or folder, and its #anchor, if any, to a heading of that file (GitHub's rule:
lower case, punctuation but '-' and '_' dropped, spaces to '-')."""
import glob
import os
import re
import shlex

import pytest

from orbed_cli import main as cli

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
PAGES = [os.path.join(ROOT, "README.md")] + sorted(glob.glob(os.path.join(ROOT, "docs", "*.md")))


def rel(path):
    return os.path.relpath(path, ROOT)


def code_blocks(text):
    """The lines inside ``` fences, with their line numbers."""
    inside = False
    for number, line in enumerate(text.splitlines(), 1):
        if line.lstrip().startswith("```"):
            inside = not inside
        elif inside:
            yield number, line


def commands():
    found = []
    for page in PAGES:
        with open(page) as f:
            text = f.read()
        for number, line in code_blocks(text):
            line = line.strip()
            if line.startswith("$ "):
                line = line[2:]
            if not line.startswith("scripts/orbed ") and line != "scripts/orbed":
                continue
            words = shlex.split(line, comments=True)
            # The command ends where the shell's next one starts (a pipe, a redirection, ...).
            for i, word in enumerate(words):
                if word in ("|", "||", "&&", ";", "&") or re.match(r"^[0-9]*[<>]", word):
                    words = words[:i]
                    break
            found.append(pytest.param(words[1:], id=f"{rel(page)}:{number}"))
    return found


@pytest.mark.parametrize("argv", commands())
def test_every_command_in_the_docs_parses(argv):
    try:
        cli.parse_args(argv)
    except SystemExit as e:
        pytest.fail(f"scripts/orbed {' '.join(argv)}: exit code {e.code}")


def anchors(path):
    """GitHub's anchors of a Markdown file's headings."""
    found = set()
    with open(path) as f:
        text = f.read()
    for line in text.splitlines():
        m = re.match(r"^#{1,6}\s+(.*?)\s*#*\s*$", line)
        if m:
            title = re.sub(r"`|\*\*|\[([^\]]*)\]\([^)]*\)", r"\1", m.group(1)).strip().lower()
            slug = re.sub(r"[^\w\- ]", "", title).replace(" ", "-")
            while slug in found:
                slug += "-1"
            found.add(slug)
    found.update(re.findall(r'<a (?:name|id)="([^"]+)"', text))
    return found


def links():
    found = []
    for page in PAGES:
        with open(page) as f:
            text = f.read()
        # Not inside code: fenced blocks and inline code spans.
        text = re.sub(r"```.*?```", "", text, flags=re.S)
        text = re.sub(r"`[^`\n]*`", "", text)
        for target in re.findall(r"\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)", text):
            if re.match(r"^[a-z][a-z0-9+.-]*:", target):  # http:, mailto:, ...
                continue
            found.append(pytest.param(page, target, id=f"{rel(page)}->{target}"))
    return found


@pytest.mark.parametrize("page, target", links())
def test_every_relative_link_resolves(page, target):
    path, _, anchor = target.partition("#")
    path = os.path.normpath(os.path.join(os.path.dirname(page), path)) if path else page
    assert os.path.exists(path), f"{rel(page)} links to {target}: no {rel(path)}"
    assert path.startswith(ROOT + os.sep) or path == ROOT, f"{rel(page)} links outside the repository: {target}"
    if anchor and path.endswith(".md"):
        assert anchor.lower() in anchors(path), f"{rel(page)} links to {target}: no heading #{anchor} in {rel(path)}"
