"""Print a Markdown table of what bt-lsp finds in a corpus of BT XML, per project.

    python scripts/corpus_report.py tests/data/corpus_real

Each project folder is checked as one workspace, the way `bt-lsp check DIR` does.
"""

from __future__ import annotations

import sys
from collections import Counter
from pathlib import Path

from bt_lsp.project.fileio import FileError, read_text
from bt_lsp.project.index import ProjectIndex, normalize
from bt_lsp.rules.codes import Severity


def main() -> int:
    root = Path(sys.argv[1] if len(sys.argv) > 1 else "tests/data/corpus_real")
    rows = []
    total: Counter[str] = Counter()
    for project in sorted(p for p in root.iterdir() if p.is_dir()):
        ws = ProjectIndex([project])
        sev: Counter[Severity] = Counter()
        codes: Counter[str] = Counter()
        files = sorted(project.glob("*.xml"))
        for f in files:
            try:
                text = read_text(str(f)).text
            except FileError:
                continue
            doc = ws.document(normalize(f))
            if doc is None or doc.text != text:
                continue
            for d in ws.diagnostics(normalize(f), doc):
                sev[d.severity] += 1
                if d.severity <= Severity.WARNING:
                    codes[d.code] += 1
        total.update(codes)
        top = ", ".join(f"`{c}` {n}" for c, n in codes.most_common(4))
        name = project.name.replace("__", "/")
        rows.append(
            f"| {name} | {len(files)} | {sev[Severity.ERROR]} | {sev[Severity.WARNING]} "
            f"| {sev[Severity.HINT] + sev[Severity.INFORMATION]} | {top} |"
        )
    print(
        "| project | files | errors | warnings | hints/info | most frequent (errors and warnings) |"
    )
    print("|---|---|---|---|---|---|")
    print("\n".join(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
