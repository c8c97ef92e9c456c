# Plots of evaluate_paper's data files; call with -e "dir='OUT_DIR'".
set terminal pngcairo size 900,560 font "DejaVu Sans,11"
set datafile missing "nan"
set key outside right top
set grid

set output dir.'/fig6_memory.png'
set title "Fig. 6: Hough-space memory over the office tour, resolution 1024"
set xlabel "frame"
set ylabel "MB (log scale)"
set logscale y
plot dir.'/fig6_memory.dat' using 1:2 with lines lw 2 title "C = 0", \
     '' using 1:3 with lines lw 2 title "C = 0.3", \
     '' using 1:4 with lines lw 2 title "C = 1.0", \
     '' using 1:5 with lines lw 2 title "C = 4.0", \
     '' using 1:6 with lines lw 2 dt 2 lc rgb "black" title "dense array"
unset logscale y

set output dir.'/fig7_accuracy.png'
set multiplot layout 1,2 title "Fig. 7: accuracy against noise C (mean and std over matched planes)"
set xlabel "noise coefficient C"
set xrange [-0.3:4.5]
set key inside left top
set title "E_{angle}"
set ylabel "rad"
plot dir.'/fig7_accuracy.dat' using ($1-0.12):2:3 with yerrorlines title "Hough 512", \
     '' using ($1-0.06):6:7 with yerrorlines title "Hough 1024", \
     '' using 1:10:11 with yerrorlines title "Hough 2048", \
     '' using ($1+0.06):14:15 with yerrorlines title "PCL RANSAC", \
     '' using ($1+0.12):18:19 with yerrorlines title "PCL OMPS"
set title "E_d"
set ylabel "m"
plot dir.'/fig7_accuracy.dat' using ($1-0.12):4:5 with yerrorlines title "Hough 512", \
     '' using ($1-0.06):8:9 with yerrorlines title "Hough 1024", \
     '' using 1:12:13 with yerrorlines title "Hough 2048", \
     '' using ($1+0.06):16:17 with yerrorlines title "PCL RANSAC", \
     '' using ($1+0.12):20:21 with yerrorlines title "PCL OMPS"
unset multiplot
set autoscale x
set key outside right top

set output dir.'/fig8_wall.png'
set title "Fig. 8: distance error to the wall while approaching it (C = 0.5)"
set xlabel "true distance to the wall (m)"
set ylabel "detected - true distance (m)"
set xrange [*:*] reverse
plot dir.'/fig8_wall.dat' using 2:($3-$2) with linespoints lw 2 pt 7 title "Hough 1024 (map)", \
     '' using 2:($4-$2) with linespoints lw 2 pt 5 title "PCL RANSAC", \
     '' using 2:($5-$2) with linespoints lw 2 pt 9 title "PCL OMPS", \
     0 with lines dt 2 lc rgb "black" notitle
set xrange [*:*] noreverse

set termoption noenhanced
set output dir.'/timing.png'
set title "Time per 640 x 480 frame, median with p10-p90 (Table 3 runs, one thread)"
set xlabel ""
set ylabel "ms (log scale)"
set logscale y
set style fill solid 0.6
set boxwidth 0.5
set xrange [-0.6:2.6]
set key off
plot dir.'/timing.dat' using 0:2:xtic(1) with boxes, '' using 0:2:3:4 with yerrorbars lc rgb "black" pt 0
