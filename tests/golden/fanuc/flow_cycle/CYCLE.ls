/PROG  CYCLE
/ATTR
OWNER		= MNEDITOR;
COMMENT		= "";
PROG_SIZE	= 0;
FILE_NAME	= ;
VERSION		= 0;
LINE_COUNT	= 69;
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
   1:  !A KRL cell cycle with every ;
   2:  !block the LS post lowers to ;
   3:  !labels and jumps: the Fanuc flow ;
   4:  !goldens (written for olp's ;
   5:  !tests). ;
   6:  R[101:nCount]=0 ;
   7:  R[104:rGap]=2.5 ;
   8:  R[105:bDone]=0 ;
   9:  PR[51,3]=R[104:rGap]*4 ;
  10:  UFRAME_NUM=0 ;
  11:  UTOOL_NUM=1 ;
  12:J P[1] 100% FINE    ;
  13:  IF DI[1]=OFF,JMP LBL[2] ;
  14:  UFRAME_NUM=0 ;
  15:  UTOOL_NUM=1 ;
  16:L P[2] 250mm/sec FINE    ;
  17:  DO[1]=ON ;
  18:  JMP LBL[3] ;
  19:  LBL[2] ;
  20:  WAIT 0.50(sec) ;
  21:  LBL[3] ;
  22:  LBL[4] ;
  23:  IF R[101:nCount]>=3 OR R[105:bDone]=1,JMP LBL[5] ;
  24:  R[101:nCount]=R[101:nCount]+1 ;
  25:  UFRAME_NUM=0 ;
  26:  UTOOL_NUM=1 ;
  27:L P[3] 250mm/sec FINE    ;
  28:  IF R[101:nCount]<2,JMP LBL[6] ;
  29:  R[105:bDone]=1 ;
  30:  LBL[6] ;
  31:  JMP LBL[4] ;
  32:  LBL[5] ;
  33:  FOR R[103:i]=1 TO 3 ;
  34:  UFRAME_NUM=0 ;
  35:  UTOOL_NUM=1 ;
  36:L P[4] 250mm/sec FINE    ;
  37:L P[5] 250mm/sec FINE    ;
  38:  ENDFOR ;
  39:  LBL[7] ;
  40:  WAIT 0.10(sec) ;
  41:  IF DI[2]=OFF AND R[101:nCount]<=5,JMP LBL[7] ;
  42:  R[102:nMode]=2 ;
  43:  SELECT R[102:nMode]=1,JMP LBL[8] ;
  44:       =2,JMP LBL[9] ;
  45:       =3,JMP LBL[9] ;
  46:       ELSE,JMP LBL[10] ;
  47:  LBL[8] ;
  48:  DO[2]=ON ;
  49:  JMP LBL[11] ;
  50:  LBL[9] ;
  51:  UFRAME_NUM=0 ;
  52:  UTOOL_NUM=1 ;
  53:L P[6] 250mm/sec FINE    ;
  54:  JMP LBL[11] ;
  55:  LBL[10] ;
  56:  DO[3]=ON ;
  57:  LBL[11] ;
  58:  LBL[12] ;
  59:  WAIT DI[3]=ON ;
  60:  IF DI[4]=ON,JMP LBL[13] ;
  61:  JMP LBL[14] ;
  62:  LBL[13] ;
  63:  JMP LBL[12] ;
  64:  LBL[14] ;
  65:  JMP LBL[1] ;
  66:  LBL[1:Finish] ;
  67:  UFRAME_NUM=0 ;
  68:  UTOOL_NUM=1 ;
  69:J P[7] 100% FINE    ;
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
	X =   550.000  mm,	Y =  -100.000  mm,	Z =   185.000  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =     0.000 deg
};
P[4]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'N U T, 0, 0, 0',
	X =   550.000  mm,	Y =   -70.000  mm,	Z =   185.000  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =     0.000 deg
};
P[5]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'N U T, 0, 0, 0',
	X =   450.000  mm,	Y =   -70.000  mm,	Z =   185.000  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =     0.000 deg
};
P[6]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'N U T, 0, 0, 0',
	X =   450.000  mm,	Y =  -100.000  mm,	Z =   185.000  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =     0.000 deg
};
P[7]{
   GP1:
	UF : 0, UT : 1,		CONFIG : 'N U T, 0, 0, 0',
	X =   450.000  mm,	Y =  -100.000  mm,	Z =   375.000  mm,
	W =   180.000 deg,	P =     0.000 deg,	R =     0.000 deg
};
/END
