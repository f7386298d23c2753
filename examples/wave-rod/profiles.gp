# Stress profiles of V1 at the four times: analytic step, uniform fine, graded, uniform coarse.
set terminal pngcairo size 1400,1000 font ",11" noenhanced
if (!exists("dir")) dir = "study"
if (!exists("scheme")) scheme = "MUSL"
set output dir."/profiles.png"
set multiplot layout 2,2 title "V1 elastic rod, ".scheme.": sigma_xx along the rod (level-2 box: 30-70 mm)"
set xlabel "x (mm)"
set ylabel "sigma_xx (MPa)"
set xrange [0:100]
set yrange [-0.05:0.55]
set grid
set key top left box opaque
set object 1 rect from 30, graph 0 to 70, graph 1 fc rgb "#eeeeee" behind
do for [t in "9 18 31 40"] {
  set title sprintf("t = %s us", t)
  plot sprintf("%s/exact_%s.dat", dir, t) w l lw 2 lc rgb "black" t "analytic", \
       sprintf("%s/uniform_fine_%s.dat", dir, t) w l lw 1.5 lc rgb "#1f77b4" t "uniform 0.25 mm", \
       sprintf("%s/graded_%s.dat", dir, t) w l lw 1.5 lc rgb "#d62728" t "graded 0.5 / 0.25 mm", \
       sprintf("%s/uniform_coarse_%s.dat", dir, t) w l lw 1 dt 2 lc rgb "#2ca02c" t "uniform 0.5 mm"
}
unset multiplot
