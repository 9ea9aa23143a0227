# Plot of the digging-force study against the fundamental earthmoving equation (docs/terrain.md).
# Data: build/examples/terrain_fee_study docs/terrain   (writes docs/terrain/fee.dat and fee_series.dat)
# Run from the repository root: gnuplot docs/terrain/fee.gp
set terminal pngcairo size 1200,520 font "sans,11"
set output "docs/terrain/fee.png"
set multiplot layout 1,2
f = "docs/terrain/fee.dat"
sel(r, w, v) = ($1 == r && abs($3 - w) < 1e-9) ? v : 1/0
set title "Horizontal force vs depth (filled: window mean; open: F0; dashed: FEE)" noenhanced
set xlabel "cutting depth d (m)"
set ylabel "horizontal force (N)"
set logscale xy
set xrange [0.025:0.08]
set yrange [2:70]
set xtics (0.03, 0.04, 0.05, 0.06, 0.07)
set grid
set key top left
plot f using (sel(45, 0.2, $2)):4 with points pt 7 ps 1.4 lc rgb "#1f77b4" title "45 deg, w 0.2 m", \
     f using (sel(45, 0.2, $2)):5 with lines lw 1.5 lc rgb "#1f77b4" dt 2 notitle, \
     f using (sel(45, 0.3, $2)):4 with points pt 5 ps 1.4 lc rgb "#d62728" title "45 deg, w 0.3 m", \
     f using (sel(45, 0.3, $2)):5 with lines lw 1.5 lc rgb "#d62728" dt 2 notitle, \
     f using (sel(60, 0.2, $2)):4 with points pt 9 ps 1.4 lc rgb "#2ca02c" title "60 deg, w 0.2 m", \
     f using (sel(60, 0.2, $2)):5 with lines lw 1.5 lc rgb "#2ca02c" dt 2 notitle, \
     f using (sel(60, 0.3, $2)):4 with points pt 11 ps 1.4 lc rgb "#9467bd" title "60 deg, w 0.3 m", \
     f using (sel(60, 0.3, $2)):5 with lines lw 1.5 lc rgb "#9467bd" dt 2 notitle, \
     f using (sel(45, 0.2, $2)):8 with points pt 6 ps 1.4 lc rgb "#1f77b4" title "F0 (open), same colours", \
     f using (sel(45, 0.3, $2)):8 with points pt 4 ps 1.4 lc rgb "#d62728" notitle, \
     f using (sel(60, 0.2, $2)):8 with points pt 8 ps 1.4 lc rgb "#2ca02c" notitle, \
     f using (sel(60, 0.3, $2)):8 with points pt 10 ps 1.4 lc rgb "#9467bd" notitle
unset logscale
set title "Horizontal force along the push, rake 45 deg, w 0.3 m (FEE: dashed)" noenhanced
set xlabel "blade travel (m)"
set ylabel "horizontal force (N), 10-step running mean"
set xrange [0:0.3]
set yrange [0:*]
set xtics auto
set key top left
s = "docs/terrain/fee_series.dat"
# Blocks in the file: rake 45 (w 0.2: d = 3, 5, 7 cm; w 0.3: 3, 5, 7), then rake 60. Index 3-5: rake 45, w 0.3.
plot s index 3 using 1:6 with lines lw 2 lc rgb "#1f77b4" title "d = 3 cm", \
     s index 4 using 1:6 with lines lw 2 lc rgb "#d62728" title "d = 5 cm", \
     s index 5 using 1:6 with lines lw 2 lc rgb "#2ca02c" title "d = 7 cm", \
     6.18268 with lines lw 1.5 lc rgb "#1f77b4" dt 2 notitle, \
     17.1741 with lines lw 1.5 lc rgb "#d62728" dt 2 notitle, \
     33.6612 with lines lw 1.5 lc rgb "#2ca02c" dt 2 notitle
unset multiplot
