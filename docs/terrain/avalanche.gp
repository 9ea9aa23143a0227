# A tall column relaxed by Terrain::avalancheAll, profile against the repose line (run from the repository root):
#   mkdir -p /tmp/heap && build/examples/terrain_avalanche_heap /tmp/heap && gnuplot -e "d='/tmp/heap'" docs/terrain/avalanche.gp
if (!exists("d")) d = "/tmp/heap"
set terminal pngcairo size 900,520 font ",10"
set output "docs/terrain/avalanche.png"
set title "4 m^3 of soil on one vertex (65 x 65 terrain, 0.1 m cells) after avalancheAll: the heap against the angle of repose"
set xlabel "distance from the apex r (m)"; set ylabel "height above the ground (m)"
set xrange [0:2.4]; set yrange [0:1.3]; set key top right; set grid
set size ratio -1
plot d."/heap_350.dat" using 1:2 with points pt 7 ps 0.6 lc rgb "#a04000" title "35 deg set: along +x", \
     d."/heap_350.dat" using 3:4 with points pt 6 ps 0.8 lc rgb "#a04000" title "35 deg set: along the diagonal", \
     d."/heap_350.dat" using 1:($5 > 0 ? $5 : 1/0) with lines lw 1.5 dt 2 lc rgb "#a04000" title "slope tan 35 deg", \
     d."/heap_266.dat" using 1:2 with points pt 7 ps 0.6 lc rgb "#2050a0" title "unset, mu = 0.5: along +x", \
     d."/heap_266.dat" using 3:4 with points pt 6 ps 0.8 lc rgb "#2050a0" title "unset, mu = 0.5: along the diagonal", \
     d."/heap_266.dat" using 1:($5 > 0 ? $5 : 1/0) with lines lw 1.5 dt 2 lc rgb "#2050a0" title "slope 0.5 = tan atan(mu)"
