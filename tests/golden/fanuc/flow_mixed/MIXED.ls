/PROG  MIXED
/ATTR
OWNER		= MNEDITOR;
COMMENT		= "";
PROG_SIZE	= 0;
FILE_NAME	= ;
VERSION		= 0;
LINE_COUNT	= 30;
MEMORY_SIZE	= 0;
PROTECT		= READ_WRITE;
TCD:  STACK_SIZE	= 0,
      TASK_PRIORITY	= 50,
      TIME_SLICE	= 0,
      BUSY_LAMP_OFF	= 0,
      ABORT_REQUEST	= 0,
      PAUSE_REQUEST	= 0;
DEFAULT_GROUP	= 1,*,*,*,*;
CONTROL_CODE	= 00000000 00000000;
/MN
   1:  !Conditions and arithmetic that ;
   2:  !need LS mixed logic (the post ;
   3:  !option mixed_logic: true): the ;
   4:  !Fanuc mixed-logic golden ;
   5:  !(written for olp's tests). ;
   6:  R[101:nParts]=0 ;
   7:  R[102:nRow]=1 ;
   8:  R[103:rPitch]=42.5 ;
   9:  UFRAME_NUM=0 ;
  10:  UTOOL_NUM=1 ;
  11:J P[1] 100% FINE    ;
  12:  LBL[1] ;
  13:  IF ((DI[1]=OFF AND DI[2]=OFF) OR R[101:nParts]>=6),JMP LBL[2] ;
  14:  R[104:rOffset]=(((R[102:nRow]-1)*R[103:rPitch])+10) ;
  15:  WAIT (DI[3]=ON AND (DI[4]=ON OR DI[5]=OFF)) ;
  16:  UFRAME_NUM=0 ;
  17:  UTOOL_NUM=1 ;
  18:L P[2] 100mm/sec FINE    ;
  19:  DO[1]=ON ;
  20:L P[3] 100mm/sec FINE    ;
  21:  R[101:nParts]=R[101:nParts]+1 ;
  22:  IF ((R[101:nParts]-(R[102:nRow]*3))<0),JMP LBL[3] ;
  23:  R[102:nRow]=R[102:nRow]+1 ;
  24:  LBL[3] ;
  25:  JMP LBL[1] ;
  26:  LBL[2] ;
  27:  R[104:rOffset]=(-1.5) ;
  28:  UFRAME_NUM=0 ;
  29:  UTOOL_NUM=1 ;
  30:J P[4] 100% FINE    ;
/POS
P[1]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'N U T, 0, 0, 0',
	X =   450.000  mm,	Y =  -100.000  mm,	Z =   275.000  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =     0.000 deg
};
P[2]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'N U T, 0, 0, 0',
	X =   450.000  mm,	Y =  -100.000  mm,	Z =   185.000  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =     0.000 deg
};
P[3]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'N U T, 0, 0, 0',
	X =   450.000  mm,	Y =  -100.000  mm,	Z =   275.000  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =     0.000 deg
};
P[4]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'N U T, 0, 0, 0',
	X =   450.000  mm,	Y =  -100.000  mm,	Z =   375.000  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =     0.000 deg
};
/END
