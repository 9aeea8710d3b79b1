"""The bench imports from ``ipmc_asym`` only names of ``ipmc_asym.__all__``: no CLI helper, no
internal module (the CLI's option helpers it needs are its own), so a change of the library's
insides cannot break it; AST of every module."""

from __future__ import annotations

import ast
from pathlib import Path

import ipmc_asym

BENCH = Path(__file__).resolve().parents[2] / "ipmc_asym_bench"


def outside_the_face(tree: ast.AST, public: set) -> list[str]:
    out, aliases = [], set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module and node.module.split(".")[0] == "ipmc_asym":
            out += [f"from {node.module} import {a.name}" for a in node.names
                    if node.module != "ipmc_asym" or a.name not in public]
        elif isinstance(node, ast.Import):
            for a in node.names:
                if a.name == "ipmc_asym":
                    aliases.add(a.asname or a.name)
                elif a.name.startswith("ipmc_asym."):
                    out.append(f"import {a.name}")
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id in aliases \
                and node.attr not in public:
            out.append(ast.unparse(node))
    return out


def test_every_import_of_the_library_is_a_public_name():
    public = set(ipmc_asym.__all__)
    files = sorted(BENCH.rglob("*.py"))
    assert files
    bad = [f"{p.name}: {u}" for p in files for u in outside_the_face(ast.parse(p.read_text(encoding="utf-8")), public)]
    assert not bad, bad


def test_the_check_can_fail():
    public = {"sweep"}
    assert outside_the_face(ast.parse("from ipmc_asym.io.jsonio import dumps\n"), public)
    assert outside_the_face(ast.parse("from ipmc_asym.cli.common import add_size_option\n"), public)
    assert outside_the_face(ast.parse("import ipmc_asym as ia\nia.closed_model_id\n"), public)
    assert not outside_the_face(ast.parse("from ipmc_asym import sweep\nimport ipmc_asym as ia\nia.sweep\n"), public)
