"""Regenerate LICENSES.md from SOURCES.tsv (run after adding files from ../shared/corpus)."""

import csv
from collections import defaultdict
from pathlib import Path

here = Path(__file__).parent
rows = list(csv.DictReader((here / "SOURCES.tsv").open(encoding="utf-8"), delimiter="\t"))
by_repo: dict[tuple[str, str, str], list[str]] = defaultdict(list)
for r in rows:
    by_repo[(r["repo"], r["license"], r["commit"])].append(r["path"])
lines = [
    "# Third-party BT XML used by the tests",
    "",
    "Byte-exact copies of files from public repositories; each file stays under the license",
    "of the repository it came from. Copyright remains with the respective authors; see each",
    "upstream repository for the full license text. `SOURCES.tsv` lists every file with its",
    "repository, path and commit; `FINDINGS.tsv` records what is known about each file.",
    "",
    "| repository | license | commit | files |",
    "|---|---|---|---|",
]
for (repo, lic, commit), paths in sorted(by_repo.items()):
    lines.append(f"| {repo} | {lic} | {commit[:12]} | {len(paths)} |")
lines.append("")
(here / "LICENSES.md").write_text("\n".join(lines), encoding="utf-8")
