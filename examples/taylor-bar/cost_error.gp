# Cost against error of the Taylor bar runs (graded.sh): |D - D_exp| and |L - L_exp| in % of
# the experiment, against mpm-run's wall time.
set terminal pngcairo size 1000,700 font ",11"
set output "study/cost_error.png"
set title "Taylor bar V2: error against the experiment vs cost (uniform 0.19, graded, uniform 0.38 mm)"
set xlabel "mpm-run wall time (s)"
set ylabel "error vs experiment (%)"
set logscale x
set grid
set key top right
set offsets graph 0.1, graph 0.3, graph 0.15, graph 0.05
plot "study/cost_error.dat" u 1:3 w p pt 7 ps 2 lc rgb "#d62728" t "foot diameter D", \
     "" u 1:3:6 w labels offset 0,1.2 notitle, \
     "" u 1:2 w p pt 5 ps 2 lc rgb "#1f77b4" t "length L", \
     "" u 1:2:6 w labels offset 0,-1.2 notitle
