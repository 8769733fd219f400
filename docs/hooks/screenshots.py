"""The pictures the pages show: `assets/screenshots/*` (where the tools write them and the
README shows them) copied into the site as `screenshots/*` at build time (mkdocs-gen-files)."""

from pathlib import Path

import mkdocs_gen_files

ROOT = Path(__file__).resolve().parents[2]

for picture in sorted((ROOT / "assets" / "screenshots").iterdir()):
    if picture.suffix in {".png", ".gif", ".jpg"}:
        with mkdocs_gen_files.open(f"screenshots/{picture.name}", "wb") as out:
            out.write(picture.read_bytes())
