"""MkDocs hook: the benchmark results in `benchmarks/results/` join the site, so that the pages' links to them
(written `../benchmarks/results/X` to work as plain files on a code host too) work on the site as well."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from mkdocs.structure.files import File, Files

RESULTS = Path(__file__).resolve().parent.parent / "benchmarks" / "results"
LINKED_AS = "](../benchmarks/results/"


def on_files(files: Files, config: Any) -> Files:
    """Each results file (Markdown pages, figures) as if it were `docs/benchmarks/results/NAME`."""
    for path in sorted(RESULTS.iterdir()):
        if path.is_file():
            files.append(File.generated(config, f"benchmarks/results/{path.name}", abs_src_path=str(path)))
    return files


def on_page_markdown(markdown: str, page: Any, config: Any, files: Files) -> str:
    """A page of docs/ links to `../benchmarks/results/X`: on the site that is `benchmarks/results/X`."""
    if "/" in page.file.src_uri:
        return markdown
    return markdown.replace(LINKED_AS, "](benchmarks/results/")
