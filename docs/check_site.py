"""Checks of a built documentation site (``python docs/check_site.py docs/_build/html``).

* No page loads a script, a style sheet or an image from another host: the site reads offline
  (MathJax is shipped in ``_static/mathjax`` by ``sphinx-mathjax-offline``).
* The API page names every public name of the package (``ipmc_asym.__all__``).

Exit status 1 with one line per problem, 0 when the site passes.
"""

from __future__ import annotations

import pathlib
import re
import sys

#: a resource the browser fetches by itself (not a link the reader may follow)
_REMOTE = re.compile(r"""(?:\bsrc\s*=\s*["']?\s*(?:https?:)?//)|(?:<link\b[^>]*\bhref\s*=\s*["']?\s*(?:https?:)?//[^>]*>)""",
                     re.I)


def remote_loads(html_dir) -> list:
    """``file: snippet`` for every page that loads a resource from another host."""
    out = []
    for page in sorted(pathlib.Path(html_dir).rglob("*.html")):
        text = page.read_text(encoding="utf-8", errors="replace")
        for m in _REMOTE.finditer(text):
            tag = m.group(0)
            if tag.lower().startswith("<link") and not re.search(r"rel\s*=\s*[\"']?(stylesheet|preload|icon)", tag, re.I):
                continue  # rel=canonical/alternate: a reference, nothing is fetched
            out.append(f"{page.relative_to(html_dir)}: {text[m.start():m.start() + 80]!r}")
    return out


def missing_api_names(html_dir, names) -> list:
    """The public names the built API page does not document (an anchor ``ipmc_asym.NAME``)."""
    api = pathlib.Path(html_dir) / "api.html"
    if not api.is_file():
        return list(names)
    text = api.read_text(encoding="utf-8", errors="replace")
    return [n for n in names if not re.search(rf"ipmc_asym\.{re.escape(n)}\b", text)]


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if len(argv) != 1:
        print("usage: python docs/check_site.py HTML_DIR", file=sys.stderr)
        return 2
    import ipmc_asym

    problems = [f"remote load: {p}" for p in remote_loads(argv[0])]
    problems += [f"api.html does not list ipmc_asym.{n}" for n in missing_api_names(argv[0], ipmc_asym.__all__)]
    for p in problems:
        print(p)
    if not problems:
        print(f"site ok: no remote loads, {len(ipmc_asym.__all__)} public names on the API page")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
