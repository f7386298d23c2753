# The extremes map (map.py writes the data): one square per case, coloured by its verdict.
# gnuplot -e "dir='study'" map.gp
if (!exists("dir")) dir = "study"
set terminal pngcairo size 1800,2300 font ",9" noenhanced
set output dir."/map.png"
load dir."/rows.gp"
set title "Extremes: verdict per case (green ran: energy error; orange stopped with exit 3; blue refused with exit 2; red silent failure; black crash)"
set xlabel "case within the family (its parameter printed in the square)"
unset key
set palette defined (1 "#8fd18f", 2 "#f5b041", 3 "#85c1e9", 4 "#e74c3c", 5 "#000000")
set cbrange [1:5]
unset colorbox
set grid noxtics noytics
plot dir."/map.dat" u 1:2:3 w p pt 5 ps 5.2 lc palette, \
     "" u 1:($2+0.18):4 w labels font ",6", \
     "" u 1:($2-0.18):5 w labels font ",6"
