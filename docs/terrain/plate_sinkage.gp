# Plot of the plate-sinkage study (docs/terrain.md). Data: build/examples/terrain_plate_study docs/terrain/plate_sinkage.dat
# Run from the repository root: gnuplot docs/terrain/plate_sinkage.gp
set terminal pngcairo size 900,600 font "sans,11"
set output "docs/terrain/plate_sinkage.png"
set title "Settled plate sinkage: Terrain (p0 = 7.18 kPa, M = 16, D = 0.121 m) vs Bekker, Wong's LLL dry sand (b = 0.5 m)"
set xlabel "plate pressure p (kPa)"
set ylabel "sinkage z (mm)"
set key top left
set grid
set xrange [0:105]
set yrange [0:90]
p0 = 7.179; a = 21.83  # mm: a = D / ((d+1) ln M) for d = 1
law(p, d) = p > p0 ? a * 2 / (d + 1) * log(p / p0) : 0
bekker(p) = 1000 * (1000 * p / (0.99e3 / 0.5 + 1528.43e3)) ** (1 / 1.1)
set samples 400
plot bekker(x) lw 3 lc rgb "black" title "Bekker p = (k_c/b + k_phi) z^n" noenhanced, \
     law(x, 0.5) lw 1.5 lc rgb "#1f77b4" dt 2 title "law, d = 0.5", \
     "docs/terrain/plate_sinkage.dat" using 1:3 with points pt 7 ps 1.2 lc rgb "#1f77b4" title "simulated, d = 0.5", \
     law(x, 1) lw 1.5 lc rgb "#d62728" dt 2 title "law, d = 1 (fit)", \
     "docs/terrain/plate_sinkage.dat" using 1:5 with points pt 5 ps 1.2 lc rgb "#d62728" title "simulated, d = 1", \
     law(x, 3) lw 1.5 lc rgb "#2ca02c" dt 2 title "law, d = 3", \
     "docs/terrain/plate_sinkage.dat" using 1:7 with points pt 9 ps 1.2 lc rgb "#2ca02c" title "simulated, d = 3"
