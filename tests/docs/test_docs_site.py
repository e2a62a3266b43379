"""The built site (``make docs``): every internal link and image resolves, every anchor
exists, and every public name has a page."""

import importlib
import re
import sys
from html.parser import HTMLParser
from pathlib import Path
from urllib.parse import unquote, urlsplit

import pytest

ROOT = Path(__file__).resolve().parents[2]
HTML = ROOT / "docs" / "_build" / "html"
sys.path.insert(0, str(ROOT / "docs" / "tools"))

pytestmark = [
    pytest.mark.docs,
    pytest.mark.skipif(
        not (HTML / "index.html").is_file(), reason="site not built (make docs builds it, then runs this)"
    ),
]


class _Page(HTMLParser):
    def __init__(self):
        super().__init__()
        self.links: list[str] = []
        self.ids: set[str] = set()

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if "id" in a:
            self.ids.add(a["id"])
        if tag == "a" and a.get("name"):
            self.ids.add(a["name"])
        for key in ("href", "src"):
            if a.get(key) and tag in ("a", "img", "link", "script"):
                self.links.append(a[key])


def _parse(path: Path) -> _Page:
    page = _Page()
    page.feed(path.read_text(errors="replace"))
    return page


def test_every_internal_link_resolves():
    pages = {p: _parse(p) for p in HTML.rglob("*.html") if "_static" not in p.relative_to(HTML).parts}
    assert len(pages) > 100
    broken = []
    for path, page in pages.items():
        for link in page.links:
            parts = urlsplit(link)
            if parts.scheme or parts.netloc or link.startswith(("mailto:", "javascript:", "data:")):
                continue
            target = (path.parent / unquote(parts.path)).resolve() if parts.path else path
            if target.is_dir():
                target = target / "index.html"
            if not target.exists():
                broken.append(f"{path.relative_to(HTML)}: {link}")
                continue
            if parts.fragment and target.suffix == ".html":
                ids = pages[target].ids if target in pages else _parse(target).ids
                if unquote(parts.fragment) not in ids:
                    broken.append(f"{path.relative_to(HTML)}: {link} (no anchor)")
    assert broken == []


def test_every_public_name_has_a_page():
    import generate

    missing = []
    for package in generate.PACKAGES:
        mod = importlib.import_module(package)
        for name in generate.public_names(mod):
            candidates = [HTML / "api" / "generated" / f"{p}.{name}.html" for p in generate.PACKAGES]
            if not any(c.is_file() for c in candidates):
                missing.append(f"{package}.{name}")
    assert missing == []


def test_gallery_made_figures_and_notebooks():
    gallery = HTML / "gallery"
    scripts = sorted((ROOT / "examples").glob("plot_*.py"))
    assert len(scripts) >= 8
    for script in scripts:
        assert (gallery / f"{script.stem}.html").is_file()
        images = list((HTML / "_images").glob(f"sphx_glr_{script.stem}_*.png"))
        assert images, f"{script.name} made no figure"
    notebooks = list((HTML / "_downloads").rglob("*.ipynb"))
    assert {n.stem for n in notebooks} >= {s.stem for s in scripts}


def test_equations_are_rendered_as_maths():
    kappa = (HTML / "physics" / "kappa.html").read_text()
    assert re.search(r'class="math', kappa)
