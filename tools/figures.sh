#!/bin/sh
# Regenerate docs/figures/, each picture from the scene that computes it:
# the pictures of configurations (knotrod render) of Figure 4 (A and B),
# Figure 5 (a stable unwalled knot at φ/2π ≈ 0.88 and X), Figure 6-right (G,
# the Appendix D knot), Figure 8-right (the strip knot) and Figure 15 (the
# Appendix E knot); then the diagrams of branches, loading paths and maps,
# named <scene>_n<N>.png (fig9_strip_3d's 3D map, hours of CPU, is not redone).
#   KNOTROD=target/debug/knotrod tools/figures.sh   (default: target/release/knotrod)
set -eu
K=${KNOTROD:-target/release/knotrod}
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
F=docs/figures

"$K" run scenes/trefoil_contact_start.toml --no-record --json "$T/contact.json" >/dev/null
"$K" render "$T/contact.json" --index 0,contact_lost --label A,B --out $F/config_fig4_A_B.png

"$K" run scenes/fig3_kirchhoff.toml --record "$T/fig3.mcap" >/dev/null
"$K" render "$T/fig3.mcap" --index phi=0.88,X --label "φ/2π ≈ 0.88",X --out $F/config_fig5_X.png

"$K" run scenes/appendix_d.toml --record "$T/d.mcap" >/dev/null
"$K" render "$T/d.mcap" --label G --out $F/config_fig6_G.png

"$K" run scenes/fig8_strip_knot.toml --record "$T/strip.mcap" >/dev/null
"$K" render "$T/strip.mcap" --label "Figure 8-right" --out $F/config_fig8_strip.png

"$K" run scenes/appendix_e.toml --record "$T/e.mcap" >/dev/null
"$K" render "$T/e.mcap" --label "Appendix E" --out $F/config_fig15_appendix_e.png
"$K" render "$T/e.mcap" --label "Appendix E (from above)" --view top --out $F/config_fig15_appendix_e_top.png

# diagrams: the PNG a run or map writes beside its --json
for s in fig3_kirchhoff:200 fig6_kirchhoff:200 fig8_strip:100 fig13_asymptotics:100 \
         loading_twist_snap:100 trefoil_contact_start:100; do
    name=${s%%:*}; n=${s##*:}
    "$K" run scenes/$name.toml --segments "$n" --no-record --json "$T/$name.json" >/dev/null
    cp "$T/$name.png" "$F/${name}_n$n.png"
    echo "diagram written to $F/${name}_n$n.png"
done
for name in fig7_island_kirchhoff fig7_island_strip; do
    "$K" map scenes/$name.toml --segments 100 --json "$T/$name.map.json" >/dev/null
    cp "$T/$name.png" "$F/${name}_n100.png"
    echo "map written to $F/${name}_n100.png"
done

# Figure 10-right: the four islands at δ = 0.10 on one plane (zero width as
# the region; the lab's ribbon, and that ribbon under its weight facing down
# and up, as curves) and the photographed knot
for name in fig10_island fig10_island_ribbon fig10_island_down fig10_island_up; do
    "$K" map scenes/$name.toml --json "$T/$name.map.json" >/dev/null 2>&1
done
"$K" plot "$T/fig10_island.map.json" "$T/fig10_island_ribbon.map.json" \
    "$T/fig10_island_down.map.json" "$T/fig10_island_up.map.json" \
    --name "(a) w = 0" --name "(b) ribbon w/L = 0.057" \
    --name "(c) ribbon, weight 25, loop down" --name "(d) ribbon, weight 25, loop up" \
    --mark "photographed knot=0.17,0.78" \
    --title "Figure 10-right: the strip's island at δ = 0.10 (N = 100, polished)" \
    --out "$T/fig10" >/dev/null
cp "$T/fig10.png" "$F/fig10_islands.png"
echo "map written to $F/fig10_islands.png"

# plastification: the ribbon's island (b) as the region, its plastified
# islands (end deflection ±5 %) and those facing down under the weight
for name in fig10_island_plastic_plus fig10_island_plastic_minus \
    fig10_island_down_plastic_plus fig10_island_down_plastic_minus; do
    "$K" map scenes/$name.toml --json "$T/$name.map.json" >/dev/null 2>&1
done
"$K" plot "$T/fig10_island_ribbon.map.json" "$T/fig10_island_plastic_plus.map.json" \
    "$T/fig10_island_plastic_minus.map.json" "$T/fig10_island_down.map.json" \
    "$T/fig10_island_down_plastic_plus.map.json" "$T/fig10_island_down_plastic_minus.map.json" \
    --name "(b) ribbon w/L = 0.057" --name "(e+) (b) plastified, û1 > 0" \
    --name "(e−) (b) plastified, û1 < 0" --name "(c) (b), weight 25, loop down" \
    --name "(f+) (c) plastified, û1 > 0" --name "(f−) (c) plastified, û1 < 0" \
    --mark "photographed knot=0.17,0.78" \
    --title "Figure 10, plastified strips (end deflection ±5 %, N = 100, polished)" \
    --out "$T/fig10_plastic" >/dev/null
cp "$T/fig10_plastic.png" "$F/fig10_plastified.png"
echo "map written to $F/fig10_plastified.png"
