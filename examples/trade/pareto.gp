# Pareto plots of the trade study (fronts.py writes the .dat files): error against CPU time of
# one thread (left) and against particle-steps (right), every run a point, the front a line.
# gnuplot -e "dir='study'" pareto.gp
if (!exists("dir")) dir = "study"
set terminal pngcairo size 1400,650 font ",10" noenhanced
set logscale xy
set grid
set key top right
set ylabel "error (%)"
do for [p in "taylor rod"] {
  set output dir."/".p."_pareto.png"
  set multiplot layout 1,2 title (p eq "taylor" ? \
    "Taylor bar V2: max(|L|, |D|) error against the experiment (surface measure)" : \
    "Wave rod V1: L1 error of sigma_xx against the analytic step (mean of 9, 18, 31, 40 us)")
  set xlabel "mpm-run CPU time, one thread (s)"
  plot dir."/".p."_points.dat" u 1:2 w p pt 7 ps 1.2 lc rgb "#888888" t "runs", \
       dir."/".p."_front.dat" u 1:2 w lp pt 7 ps 1.6 lw 2 lc rgb "#d62728" t "front", \
       "" u 1:2:3 w labels left offset 0.6,0.5 font ",8" notitle, \
       1 w l dt 2 lc rgb "#1f77b4" t "1%", 2 w l dt 2 lc rgb "#2ca02c" t "2%", \
       5 w l dt 2 lc rgb "#9467bd" t "5%"
  set xlabel "particle-steps (load-independent cost)"
  plot dir."/".p."_points.dat" u 3:2 w p pt 7 ps 1.2 lc rgb "#888888" t "runs", \
       dir."/".p."_front_ps.dat" u 1:2 w lp pt 7 ps 1.6 lw 2 lc rgb "#d62728" t "front", \
       "" u 1:2:3 w labels left offset 0.6,0.5 font ",8" notitle, \
       1 w l dt 2 lc rgb "#1f77b4" t "1%", 2 w l dt 2 lc rgb "#2ca02c" t "2%", \
       5 w l dt 2 lc rgb "#9467bd" t "5%"
  unset multiplot
}
