"""Link checks shared by the report tests (not a test module)."""

import re
from pathlib import Path


def links(text: str) -> list[str]:
    """Targets of markdown links/images and of HTML src/href attributes."""
    md = re.findall(r"!?\[[^\]]*\]\(([^)\s]+)\)", text)
    html = re.findall(r"(?:src|href)=\"([^\"]+)\"", text)
    return md + html


def assert_links_resolve(text: str, base: Path) -> None:
    for target in links(text):
        if target.startswith(("data:", "#", "http://", "https://")):
            continue
        assert (base / target).is_file(), f"link to a missing file: {target}"
