"""The ray tree of `rtcli explain` as text (docs/debugging.md): one ray a block, its terms under it,
its secondary rays nested, and the sum at the foot of every block. The tree's types (raytree.py)
print themselves through these functions, which read their fields and import nothing of them.

`style(text, role)` colors a piece by its role (ray, miss, term, sum, note); the command line
passes click.style's colors, which it shows only on a terminal.
"""

from __future__ import annotations

import numpy as np

BRANCH, PIPE, INDENT = "├─ ", "│  ", "   "


def num(x: float) -> str:
    return "0" if x == 0 else f"{x:.6g}"


def vec(v) -> str:
    return "(" + ", ".join(num(float(c)) for c in v) + ")"


def format_explanation(e, sample: int | None, style) -> str:
    """The pixel's line, then the tree of the sample asked for (every sample for None)."""
    per_pixel = e.samples ** 2
    lines = [style(f"pixel ({e.x}, {e.y}) of {e.width}x{e.height} = {vec(e.value)}", "sum")
             + f" -> 8-bit {tuple(int(b) for b in e.byte)}" + (" (sRGB)" if e.gamma else "")]
    if per_pixel == 1:
        lines.append(style(f"one sample, through ({num(e.positions[0, 0])}, {num(e.positions[0, 1])})", "note"))
    else:
        lines.append(style(f"the mean of {per_pixel} samples ({e.samples} x {e.samples}, jittered); "
                           + ("showing every one" if sample is None else
                              f"showing sample {sample} (--sample K for another, --all-samples for all)"), "note"))
    for k in range(per_pixel) if sample is None else [sample]:
        lines.append("")
        if per_pixel > 1:
            lines.append(style(f"sample {k} at ({num(e.positions[k, 0])}, {num(e.positions[k, 1])})", "note"))
        lines += node_lines(e.trees[k], style, "N.H" if e.specular == "blinn" else "R.V")
    return "\n".join(lines)


def node_lines(node, style, cos_name: str = "R.V") -> list[str]:
    head = f"{node.kind} ray, depth {node.depth}: from {vec(node.origin)} along {vec(node.direction)}"
    out = [style(head, "ray")]
    if node.more:
        return out + [INDENT + style(f"… {node.more:,} more rays (this one and those below it, past the node "
                                     f"budget: --max-nodes), total contribution {vec(node.contribution())}", "note")]
    if node.hit is None:
        out.append(INDENT + style(f"misses every object: the background {vec(node.value)}", "miss"))
        return out
    h, c = node.hit, node.hit.coefficients
    out.append(INDENT + f"hits #{h.object} {h.name or '(unnamed)'} ({h.shape}) at t = {num(h.t)}, "
               f"point {vec(h.point)}, {'entering' if h.entering else 'leaving (from inside)'}")
    out.append(INDENT + f"normal N {vec(h.normal)}, geometric {vec(h.geometric)}")
    mat = [f"ka {vec(c['ka'])}", f"kd {vec(c['kd'])}", f"ks {vec(c['ks'])}", f"n {num(c['n'])}"]
    if np.any(c["kr"]):
        mat.append(f"kr {vec(c['kr'])}")
    if np.any(c["kt"]) or c["fresnel"]:
        mat += [f"kt {vec(c['kt'])}", f"ior {num(c['ior'])}"] + (["fresnel"] if c["fresnel"] else [])
    out.append(INDENT + f"material {h.material_name}: " + ", ".join(mat))
    out.append(INDENT + f"texture T {vec(h.texture)}" + (f" ({c['texture']})" if c["texture"] else ""))
    out.append(INDENT + _term("emission", node.emission, style))
    out.append(INDENT + _term("ka Ia T", node.ambient_term, style))
    for light in node.lights:
        out += [INDENT + line for line in light_lines(light, style, cos_name)]
    out.append(INDENT + _term("local", node.local(), style, "sum"))
    if node.glass is not None:
        out.append(INDENT + style(glass_line(node.glass), "note"))
    if node.stopped:
        out.append(INDENT + style(f"max_depth {node.depth} reached: no reflected or refracted ray", "note"))
    for cut in node.bailouts:
        out.append(INDENT + style(f"{cut.kind} ray not traced: its path weight {vec(cut.path)} is below "
                                  f"adc_bailout {num(cut.adc_bailout)}", "note"))
    parts = [f"local {vec(node.local())}"]
    for child in node.children:
        w = "wr" if child.kind == "reflected" else "wt"
        out.append(INDENT + BRANCH + f"{w} {vec(child.weight)} x")
        sub = node_lines(child, style, cos_name)
        out += [INDENT + PIPE + line for line in sub]
        parts.append(f"{w} x {child.kind} {vec(child.weight * child.total())}")
    if node.children:
        out.append(INDENT + style("= " + " + ".join(parts), "note"))
    out.append(INDENT + _term("=", node.total(), style, "sum"))
    return out


def light_lines(light, style, cos_name: str) -> list[str]:
    out = [f"light {light.index} ({light.kind} at {vec(light.position)}, I {vec(light.color)})"]
    if len(light.samples) == 1:
        s = light.samples[0]
        geometry = f"N.L {num(s.NL)}, r {num(s.r)}, attenuation {num(s.attenuation)}"
        if light.kind == "spot":
            geometry += f", spot {num(s.spot)}" + (" (outside the cone)" if s.spot == 0 else "")
        if s.feeler is None:
            return out + [INDENT + geometry + style(": N.L <= 0, the surface faces away from it", "note")]
        out.append(INDENT + geometry + ", feeler " + feeler_text(s.feeler))
        if s.lit:
            out.append(INDENT + _term("diffuse  w (N.L) I kd T", s.diffuse, style))
            if s.cos is not None:
                out.append(INDENT + _term(f"specular w ({cos_name})^n I ks", s.specular, style)
                           + style(f"  {cos_name} {num(s.cos)}", "note"))
        return out
    away = sum(s.feeler is None for s in light.samples)
    lit = sum(s.lit for s in light.samples)
    dark = [s for s in light.samples if s.feeler is not None and not s.lit]
    blockers = sorted({f"#{s.feeler.blocker} {s.feeler.blocker_name}".strip() for s in dark if s.feeler.blocker})
    summary = (f"{len(light.samples)} samples: {lit} lit, {len(dark)} in shadow"
               + (f" (by {', '.join(blockers)})" if blockers else "") + f", {away} facing away")
    facing = [s for s in light.samples if s.feeler is not None]
    if facing:
        summary += (f"; mean N.L {num(np.mean([s.NL for s in facing]))}, "
                    f"r {num(np.mean([s.r for s in facing]))}, "
                    f"attenuation {num(np.mean([s.attenuation for s in facing]))}, "
                    f"w {num(np.mean([s.weight for s in facing]))}")
    out.append(INDENT + summary)
    out.append(INDENT + _term("diffuse  (sum over samples)", light.diffuse(), style))
    if any(s.cos is not None for s in light.samples):
        out.append(INDENT + _term("specular (sum over samples)", light.specular(), style))
    return out


def feeler_text(f) -> str:
    if f.state == "clear":
        return "clear"
    who = f" by #{f.blocker} {f.blocker_name} at t = {num(f.blocker_t)}" if f.blocker else ""
    if f.state == "blocked":
        return "blocked" + who
    return f"filtered{who}, lets through {vec(f.through)}"


def glass_line(g) -> str:
    """Snell's numbers, and what weighs the two rays: Fresnel's R, or the material's kr and kt."""
    text = (f"glass: n1 {num(g.n1)} -> n2 {num(g.n2)}, incidence {g.theta_i:.4g} deg, ")
    if g.tir:
        return text + "total internal reflection (no refracted ray)"
    weights = f"Fresnel R {num(g.R)}" if g.fresnel else "weights kr and kt as given (fresnel: false)"
    return text + f"refraction {g.theta_t:.4g} deg, {weights}"


def _term(label: str, value, style, role: str = "term") -> str:
    return f"{label:<30} " + style(vec(value), role)
