# Side view of examples/terrain_dig_trench at the end of each phase (run from the repository root):
#   mkdir -p /tmp/dig && build/examples/terrain_dig_trench /tmp/dig && gnuplot -e "d='/tmp/dig'" docs/terrain/dig.gp
if (!exists("d")) d = "/tmp/dig"
set terminal pngcairo size 1000,760 font ",10"
set output "docs/terrain/dig.png"
set multiplot layout 2,2 title "A kinematic bucket digs a trench; the soil becomes particles and merges back (side view, y = 0)"
set xrange [-2:2]; set yrange [-0.3:1.0]; set size ratio -1
set xlabel "x (m)"; set ylabel "z (m)"; set key top left
do for [ph in "dig lift dump settle"] {
  set title "end of ".ph
  plot d."/".ph."_surface.dat" with filledcurves y1=-0.2 lc rgb "#c79a55" title "terrain", \
       d."/".ph."_particles.dat" with points pt 7 ps 0.5 lc rgb "#5a3410" title "particles", \
       d."/".ph."_bucket.dat" with lines lw 2 lc rgb "#303080" title "bucket"
}
unset multiplot
