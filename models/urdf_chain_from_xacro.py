"""Write the joint chain of a ROS-Industrial ``*_macro.xacro`` as a plain URDF.

The welding-robot library's URDFs (``models/<robot>/<robot>.urdf``) were written by this script
from the macros of ROS-Industrial's support packages: the links and joints as published, the
``${prefix}`` removed and each ``${...}`` expression evaluated (``pi``, ``radians``), the visual
and collision meshes, materials and inertials left out (none of these macros has inertials).

    python models/urdf_chain_from_xacro.py MACRO.xacro OUT.urdf --name NAME --source "TEXT"

``--source`` is the comment written at the top of the URDF (repository, commit, path, licence).
"""

from __future__ import annotations

import argparse
import math
import re
import xml.etree.ElementTree as ET
from pathlib import Path

_NAMES = {"pi": math.pi, "radians": math.radians, "degrees": math.degrees}
_DROP = {"visual", "collision", "inertial", "material"}


def _evaluate(text: str) -> str:
    """``text`` with ``${prefix}`` removed and every ``${expr}`` replaced by its value."""
    text = text.replace("${prefix}", "")

    def value(m: re.Match[str]) -> str:
        return repr(float(eval(m.group(1), {"__builtins__": {}}, _NAMES)))

    return re.sub(r"\$\{([^}]*)\}", value, text)


def chain_urdf(macro: Path, name: str, source: str) -> str:
    """The plain URDF text of the macro's links and joints."""
    root = ET.fromstring(macro.read_text(encoding="utf-8"))
    body = next(el for el in root.iter() if el.tag.endswith("macro"))
    links, joints = [], []
    for el in body:
        if el.tag == "link":
            links.append(f'<link name="{_evaluate(el.get("name", ""))}"/>')
        elif el.tag == "joint":
            parts = [f'<joint name="{_evaluate(el.get("name", ""))}" type="{el.get("type")}">']
            for child in el:
                if child.tag in _DROP:
                    continue
                attrs = " ".join(f'{k}="{_evaluate(v)}"' for k, v in child.attrib.items())
                parts.append(f"<{child.tag} {attrs}/>")
            joints.append(" ".join(parts) + " </joint>")
    return "\n".join(['<?xml version="1.0"?>', f"<!-- {source} -->", f'<robot name="{name}">',
                      "  " + " ".join(links)] + ["  " + j for j in joints] + ["</robot>", ""])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("macro", type=Path)
    ap.add_argument("out", type=Path)
    ap.add_argument("--name", required=True)
    ap.add_argument("--source", required=True)
    args = ap.parse_args()
    args.out.write_text(chain_urdf(args.macro, args.name, args.source), encoding="utf-8")


if __name__ == "__main__":
    main()
