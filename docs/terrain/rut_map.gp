# Depth map of the ruts after examples/terrain_rut_map (run from the repository root):
#   build/examples/terrain_rut_map docs/terrain/rut_map.dat && gnuplot docs/terrain/rut_map.gp
set terminal pngcairo size 900,520 font ",10"
set output "docs/terrain/rut_map.png"
set title "Ruts after one 4 s pass of the tire-model vehicle (Terrain, 0.1 m cells, deformability 1)"
set xlabel "x (m)"; set ylabel "y (m)"; set cblabel "depth below the original surface (mm)"
set view map; set size ratio -1
set xrange [-2:8]; set yrange [-2:2]
set palette defined (0 "#f4e8c8", 5 "#c79a55", 15 "#7a4a1c", 30 "#2b1406")
splot "docs/terrain/rut_map.dat" using 1:2:3 with pm3d notitle
