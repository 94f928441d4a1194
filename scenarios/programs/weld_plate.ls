/PROG  LRMATE200IC_WELD_PLATE
/ATTR
COMMENT		= "lrmate200ic_weld";
PROG_SIZE	= 0;
FILE_NAME	= ;
VERSION		= 0;
LINE_COUNT	= 15;
MEMORY_SIZE	= 0;
PROTECT		= READ_WRITE;
DEFAULT_GROUP	= 1,*,*,*,*;
/MN
   1:  UFRAME_NUM=0 ;
   2:  UTOOL_NUM=1 ;
   3:  J P[1] 19% FINE ;
   4:  J P[2] 5% FINE ;
   5:  Arc Start[1] ;
   6:  L P[3] 8mm/sec FINE ;
   7:  Arc End[1] ;
   8:  L P[4] 100mm/sec FINE ;
   9:  J P[5] 17% FINE ;
  10:  L P[6] 100mm/sec FINE ;
  11:  Arc Start[1] ;
  12:  C P[8] ;
    :  P[7] 8mm/sec FINE ;
  13:  Arc End[1] ;
  14:  L P[9] 100mm/sec FINE ;
  15:  J P[10] 19% FINE ;
/POS
P[1]{
   GP1:
	UF : 0, UT : 1,
	J1=    -30.000 deg,	J2=     -8.000 deg,	J3=    -42.000 deg,
	J4=      0.000 deg,	J5=    -45.000 deg,	J6=      0.000 deg
};
P[2]{
   GP1:
	UF : 0, UT : 1,
	J1=    -32.000 deg,	J2=     -8.083 deg,	J3=    -49.746 deg,
	J4=      0.000 deg,	J5=    -30.254 deg,	J6=      0.000 deg
};
P[3]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 0',
	X =    432.505  mm,	Y =   -270.259  mm,	Z =    -90.000  mm,
	W =    180.000 deg,	P =    -10.000 deg,	R =    -32.000 deg
};
P[4]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'F U T, 0, 0, 0',
	X =    432.500  mm,	Y =   -270.260  mm,	Z =      0.000  mm,
	W =    180.000 deg,	P =    -10.000 deg,	R =    -32.000 deg
};
P[5]{
   GP1:
	UF : 0, UT : 1,
	J1=     -5.000 deg,	J2=     -4.876 deg,	J3=    -54.351 deg,
	J4=      0.001 deg,	J5=      9.351 deg,	J6=     89.999 deg
};
P[6]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'N U T, 0, 0, 0',
	X =    498.097  mm,	Y =    -43.578  mm,	Z =   -150.000  mm,
	W =    135.000 deg,	P =      0.000 deg,	R =     85.000 deg
};
P[7]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'N U T, 0, 0, 0',
	X =    353.553  mm,	Y =    353.553  mm,	Z =   -150.000  mm,
	W =    135.000 deg,	P =      0.000 deg,	R =    135.000 deg
};
P[8]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'N U T, 0, 0, 0',
	X =    469.846  mm,	Y =    171.010  mm,	Z =   -150.000  mm,
	W =    135.000 deg,	P =      0.000 deg,	R =    110.000 deg
};
P[9]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'N U T, 0, 0, 0',
	X =    353.550  mm,	Y =    353.550  mm,	Z =    -60.000  mm,
	W =    135.000 deg,	P =      0.000 deg,	R =    135.000 deg
};
P[10]{
   GP1:
	UF : 0, UT : 1,
	J1=      0.000 deg,	J2=      0.000 deg,	J3=      0.000 deg,
	J4=      0.000 deg,	J5=    -90.000 deg,	J6=      0.000 deg
};
/END
