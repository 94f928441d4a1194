/PROG  WELD1
/ATTR
OWNER		= MNEDITOR;
COMMENT		= "test weld";
DEFAULT_GROUP	= 1,*,*,*,*;
/MN
   1:  UFRAME_NUM=0 ;
   2:  UTOOL_NUM=1 ;
   3:  J P[1] 50% FINE    ;
   4:  L P[2] 100mm/sec FINE    ;
   5:  Arc Start[1] ;
   6:  L P[3] 10mm/sec CNT50    ;
   7:  C P[4]    ;
    :  P[5] 10mm/sec FINE    ;
   8:  Arc End[1] ;
   9:  WAIT 0.50(sec) ;
  10:  DO[1]=ON ;
  11:  J P[6] 30% FINE    ;
/POS
P[1]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'N U T, 0, 0, 0',
	X =   450.000  mm,	Y =   -50.000  mm,	Z =    50.000  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =     0.000 deg
};
P[2]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'N U T, 0, 0, 0',
	X =   450.000  mm,	Y =   -50.000  mm,	Z =     0.000  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =     0.000 deg
};
P[3]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'N U T, 0, 0, 0',
	X =   450.000  mm,	Y =    50.000  mm,	Z =     0.000  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =     0.000 deg
};
P[4]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'N U T, 0, 0, 0',
	X =   500.000  mm,	Y =   100.000  mm,	Z =     0.000  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =     0.000 deg
};
P[5]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'N U T, 0, 0, 0',
	X =   550.000  mm,	Y =    50.000  mm,	Z =     0.000  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =     0.000 deg
};
P[6]{
   GP1:
	UF : 0, UT : 1,	
	J1=     0.000 deg,	J2=     0.000 deg,	J3=     0.000 deg,
	J4=     0.000 deg,	J5=   -90.000 deg,	J6=     0.000 deg
};
/END
